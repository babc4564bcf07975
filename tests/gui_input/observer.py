# Started with FreeCAD's GUI by the real-input tests (`freecad observer.py`): every 100 ms it writes
# what a test asserts on (documents, sculpts, undo lists, the workbench's state, where the 3D views
# are) to $HS_OBSERVER_OUT as JSON. It only reads: every action in those tests is a real X event.
import json
import os
import sys

import FreeCAD
import FreeCADGui as Gui
from pivy import coin

import HapticSculpt

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HapticSculpt.__file__)), "tests", "gui_input"))
from observer_digest import digest  # noqa: E402

OUT = os.environ["HS_OBSERVER_OUT"]


def _sculpts(doc):
    out = []
    for o in doc.Objects:
        if getattr(getattr(o, "Proxy", None), "Type", None) != "HapticSculpt::Sculpt":
            continue
        settings = json.loads(o.SculptSettings)
        face = o.Shape.Faces[0].Surface if o.Shape.Faces else None
        out.append({"name": o.Name, "label": o.Label, "poles": list(o.Poles), "strokes": o.Strokes,
                    "shape_poles": [[p.x, p.y, p.z] for row in face.getPoles() for p in row] if face else [],
                    "constraints": [[c["kind"], c["index"]] for c in settings.get("constraints", [])],
                    "plasticity": settings.get("plasticity"), "tool": settings.get("tool", {}).get("name"),
                    "stiffness_map": [min(o.StiffnessMap), max(o.StiffnessMap), len(o.StiffnessMap)],
                    "stiffness_values": list(o.StiffnessMap), "shown_stiffness": _shown_map(o, "stiffness"),
                    "bending_map": [min(o.BendingMap), max(o.BendingMap), len(o.BendingMap)]
                    if hasattr(o, "BendingMap") else [], "edges": _held_edges(o),
                    "session": o.Proxy.live.session is not None if getattr(o.Proxy, "live", None) else False,
                    "device": o.Proxy.live.session.device_name
                    if getattr(o.Proxy, "live", None) and o.Proxy.live.session else "",
                    "haptic_rate": o.Proxy.live.session.haptic_rate
                    if getattr(o.Proxy, "live", None) and o.Proxy.live.session else 0.0,
                    "simulated_s": o.Proxy.live.session.simulated_seconds
                    if getattr(o.Proxy, "live", None) and o.Proxy.live.session else 0.0,
                    "selected": o in Gui.Selection.getSelection(), "screen": _on_screen(o), "digest": digest(o),
                    "drawn_poles": _drawn_poles(o), "curves": _curves(o),
                    "target": o.Target.Name if getattr(o, "Target", None) is not None else None,
                    "pull": settings.get("pull", [True, 1.0]),
                    "pull_map": [min(o.PullMap), max(o.PullMap), len(o.PullMap)]
                    if getattr(o, "PullMap", None) else [],
                    "deviation": json.loads(o.Deviation) if getattr(o, "Deviation", "") else {}})
    return out


def _curves(o):
    """The curves the sculpt follows: [continuity, distance (mm), normal angle (degrees)] each."""
    try:
        return [[c["continuity"], c["distance_mm"], c["normal_deg"]] for c in HapticSculpt.curve_constraints_of(o)]
    except Exception:  # noqa: BLE001 - a stored state being read
        return []


def _held_edges(o):
    """How the sculpt's four edges are held (HapticSculpt.held_boundary), {} for a face of a solid."""
    try:
        return HapticSculpt.held_boundary(o)
    except Exception:  # noqa: BLE001 - a face sculpted in its solid, or a state being read
        return {}


def _shown_map(o, name):
    """[min, max, count] of the map the displays show (a running session's spray included)."""
    try:
        values = o.Proxy.live.map_values(name)
        return [float(values.min()), float(values.max()), int(values.size)]
    except Exception:  # noqa: BLE001 - a stored state being read
        return []


def _drawn_poles(o):
    """The poles the overlays draw the sculpt from (its live surface's newest state), as a flat list."""
    live = getattr(getattr(o, "Proxy", None), "live", None)
    if live is None:
        return []
    try:
        return [float(x) for x in __import__("numpy").asarray(live.snapshot().poles).ravel()]
    except Exception:  # noqa: BLE001 - a stored state being read
        return []


def _shape_facts(doc):
    """{name: (shape, valid, volume)} of every object with a shape, each checked once a write (the
    check is the observer's dearest part)."""
    out = {}
    for o in doc.Objects:
        shape = getattr(o, "Shape", None)
        if shape is None or not hasattr(shape, "Solids"):
            continue
        null = shape.isNull()
        out[o.Name] = (shape, not null and shape.isValid(), 0.0 if null else shape.Volume)
    return out


def _solids(doc, facts):
    out = []
    for o in doc.Objects:
        if getattr(getattr(o, "Proxy", None), "Type", None) != "HapticSculpt::SculptedSolid":
            continue
        shape, valid, volume = facts[o.Name]
        out.append({"name": o.Name, "valid": valid, "solids": len(shape.Solids),
                    "closed": all(sh.isClosed() for sh in shape.Shells), "volume": volume,
                    "faces": len(shape.Faces), "wires": sorted(len(f.Wires) for f in shape.Faces),
                    "seams": json.loads(o.SeamReport or "[]"), "error": o.RebuildError,
                    "sculpt_faces": list(o.SculptFaces), "mirror_mm": _mirror_distance(o),
                    "boundary": json.loads(o.Boundary or "{}"),
                    "base_visible": bool(o.Base.ViewObject.Visibility) if o.Base is not None else None})
    return out


def _features(doc, facts):
    """Every object with a shape: its type, recompute state and what its shape is (and a Thickness's
    thickness)."""
    out = {}
    for o in doc.Objects:
        if o.Name not in facts:
            continue
        shape, valid, volume = facts[o.Name]
        out[o.Name] = {"type": o.TypeId, "state": list(o.State), "valid": valid,
                       "solids": len(shape.Solids), "volume": volume,
                       "zmax": shape.BoundBox.ZMax if not shape.isNull() else None,
                       "thickness": o.Thickness.Value if hasattr(o, "Thickness") else None,
                       "visible": bool(o.ViewObject.Visibility) if o.ViewObject is not None else None}
    return out


_TREE = []


def _tree_items():
    """Where each item of the model tree is on the screen ({label: [x, y]}, its centre, in the
    screen's pixels: Qt's are scaled by the device pixel ratio), for a double-click on it (found by
    class name: no Qt import)."""
    if not _TREE:
        stack = list(Gui.getMainWindow().children())
        while stack:
            w = stack.pop()
            if hasattr(w, "metaObject") and w.metaObject().className() == "Gui::TreeWidget":
                _TREE.append(w)  # (the combo view's and the tree view's, which is hidden)
            stack.extend(w.children())
    tree, out = next((t for t in _TREE if t.isVisible()), None), {}
    if tree is None:
        return out
    # (walked through the model's indices, plain values: PySide6 wrappers of the items themselves, as
    # FreeCAD 1.1's tree rebuilds them, were found already deleted while walked)
    model = tree.model()
    indices = [model.index(k, 0) for k in range(model.rowCount())]
    while indices:
        index = indices.pop()
        indices.extend(model.index(k, 0, index) for k in range(model.rowCount(index)))
        rect = tree.visualRect(index)
        if rect.height() > 0:
            p, scale = tree.viewport().mapToGlobal(rect.center()), tree.devicePixelRatioF()
            out[model.data(index)] = [round(p.x() * scale), round(p.y() * scale)]
    return out


def _mirror_distance(o):
    """How far a symmetric SculptedSolid's sculpted face is from its own mirror image (None if it
    has no mirror plane), on a 21 x 21 grid."""
    sym = json.loads(getattr(o, "Symmetry", "") or "null")
    if not sym or not o.Sculpts:
        return None
    from HapticSculpt.app.sculpted_solid import sculpted_surface
    s = sculpted_surface(o.Sculpts[0])
    p0, n = FreeCAD.Vector(*sym["point"]), FreeCAD.Vector(*sym["normal"])
    u0, u1, v0, v1 = s.bounds()
    worst = 0.0
    for i in range(21):
        for j in range(21):
            u, v = u0 + (u1 - u0) * i / 20, v0 + (v1 - v0) * j / 20
            p = s.value(u, v)
            q = s.value(u0 + u1 - u, v) if sym["direction"] == 0 else s.value(u, v0 + v1 - v)
            worst = max(worst, (p - n * (2 * (p - p0).dot(n)) - q).Length)
    return worst


def _on_screen(o):
    """Where the sculpt's centre and corners are in the active 3D view's viewport (its pixels)."""
    try:
        view = Gui.ActiveDocument.ActiveView
        bb = o.Shape.BoundBox
        pts = [FreeCAD.Vector(bb.Center.x, bb.Center.y, bb.ZMax)]
        pts += [FreeCAD.Vector(bb.Center.x + fx * bb.XLength / 2, bb.Center.y + fy * bb.YLength / 2, bb.ZMax)
                for fx, fy in ((0.5, 0), (-0.5, 0), (0, 0.5), (0, -0.5))]
        return [list(view.getPointOnScreen(p)) for p in pts]
    except Exception:  # noqa: BLE001 - no active 3D view
        return []


def _probed_points():
    """Where the 3D points a test asked about (the JSON list in OUT.points: [x, y, z] each) are in
    the active 3D view's viewport, as [request id, [[x, y], ...]]; None when none were asked."""
    try:
        with open(OUT + ".points") as f:
            request = json.load(f)
        view = Gui.ActiveDocument.ActiveView
        return [request["id"], [list(view.getPointOnScreen(FreeCAD.Vector(*p))) for p in request["points"]]]
    except Exception:  # noqa: BLE001 - nothing asked, or no 3D view yet
        return None


def _preselection():
    """What the mouse highlights: [object name, sub-element] or None."""
    pre = Gui.Selection.getPreselection()
    return [pre.ObjectName, pre.SubElementNames[0] if pre.SubElementNames else ""] if pre.ObjectName else None


def _edge_points(o):
    """Where points of a curve object's edges (a sketch, a wire: edges and no faces) are in the
    active 3D view's viewport, to click it: each edge's middle first, then its thirds (a point a
    click misses has others to try)."""
    try:
        if o.Shape.Faces or not o.Shape.Edges:
            return []
        view = Gui.ActiveDocument.ActiveView
        return [list(view.getPointOnScreen(e.valueAt(e.FirstParameter + t * (e.LastParameter - e.FirstParameter))))
                for t in (0.5, 1 / 3, 2 / 3) for e in o.Shape.Edges]
    except Exception:  # noqa: BLE001 - no active 3D view
        return []


_pixels = {}  # id(view) -> [the mouse's last position in its viewport pixels, as Coin's events give it]


def _pixel(v):
    """Where the view's own events put the mouse (the HUD's pixels; FreeCAD 0.20's getCursorPos
    differed from them by 4 % and more: a calibration on it put drags beside the sliders)."""
    if id(v) not in _pixels:
        _pixels[id(v)] = [None, v.addEventCallbackPivy(
            coin.SoLocation2Event.getClassTypeId(),
            lambda cb, key=id(v): _pixels[key].__setitem__(0, list(cb.getEvent().getPosition())))]
    return _pixels[id(v)][0]


_renders = {}  # id(view) -> [the number of times Coin drew its scene, the callback node counting them]


def _rendered(v):
    """How many times the view's scene has been drawn (a GL render traversal of its root): a picture
    taken after this grew shows what the scene graph held before it did, whatever Qt's paint timing."""
    if id(v) not in _renders:
        counter = [0, coin.SoCallback()]

        def count(_, action, counter=counter):
            if action.isOfType(coin.SoGLRenderAction.getClassTypeId()):
                counter[0] += 1
        counter[1].setCallback(count)
        v.getSceneGraph().insertChild(counter[1], 0)
        _renders[id(v)] = counter
    return _renders[id(v)][0]


def _views():
    out = []
    for name in FreeCAD.listDocuments():
        gdoc = Gui.getDocument(name)
        for v in gdoc.mdiViewsOfType("Gui::View3DInventor") if gdoc else []:
            try:
                out.append({"doc": name, "size": list(v.getSize()), "cursor": list(v.getCursorPos()),
                            "pixel": _pixel(v), "renders": _rendered(v),
                            "camera": v.getCamera(),
                            "active": v is getattr(Gui.ActiveDocument, "ActiveView", None), "id": id(v),
                            "redirect": bool(v.getViewer().isRedirectedToSceneGraph())})
            except Exception:  # noqa: BLE001 - a view closing
                pass
    return out


def _task_buttons():
    """The visible buttons of the open task dialog (OK, Cancel, ...) by text, at their centres in
    screen pixels; empty when there is none. (Walked from the main window: no Qt import in the project.)"""
    if not Gui.Control.activeDialog():
        return {}
    found, stack = {}, [Gui.getMainWindow()]
    while stack:
        w = stack.pop()
        name = w.metaObject().className()
        if name == "Gui::TaskView::TaskView":
            stack = [w]  # (only its buttons: the main window has others with the same texts)
            found.clear()
            w = stack.pop()
        if name == "QPushButton" and w.isVisible() and w.text():
            centre, ratio = w.mapToGlobal(w.rect().center()), w.devicePixelRatioF()  # (Qt's pixels to the screen's)
            found[w.text().replace("&", "")] = [round(centre.x() * ratio), round(centre.y() * ratio)]
        stack.extend(c for c in w.children() if c.isWidgetType())
    return found


def _rect(widget, rect=None):
    """[x, y, width, height] of a widget (or of ``rect`` in its coordinates) in screen pixels (Qt
    counts in its own units: Xvfb's 100 dpi make Qt scale them by 100/96)."""
    rect = rect if rect is not None else widget.rect()
    corner, scale = widget.mapToGlobal(rect.topLeft()), widget.devicePixelRatioF()
    return [round(corner.x() * scale), round(corner.y() * scale), round(rect.width() * scale),
            round(rect.height() * scale)]


def _command_name(action):
    """The command a toolbar or menu action runs (a group's entries name theirs in a property)."""
    name = action.property("CommandName")
    if name is None:
        return action.objectName()
    if isinstance(name, str):
        return name
    return bytes(name if isinstance(name, bytes) else name.data()).decode()  # (a QByteArray: PySide2 and 6)


def _entries(menu):
    """The entries of a drop-down or menu, by command name: their place if it is open, else None."""
    return {_command_name(a): _rect(menu, menu.actionGeometry(a)) if menu.isVisible() else None
            for a in menu.actions() if not a.isSeparator() and a.isVisible()}


def _toolbars():
    """What the main window shows of the toolbars and menus, read through FreeCAD's main window
    object (no Qt import): each shown toolbar's buttons on screen by command name (a group's
    button also lists its drop-down's entries), the buttons it hides behind its "»" extension and
    where that is, and the open drop-down or menu's entries."""
    mw = Gui.getMainWindow()
    bars, buttons, groups, open_menus = {}, {}, {}, {}
    disabled: list = []  # (a drop-down's entries that are greyed out)
    for bar in mw.children():
        if not bar.inherits("QToolBar") or not bar.isVisible():  # (FreeCAD 1.0's are Gui::ToolBar)
            continue
        shown, hidden, extension = [], [], None
        for tb in bar.children():
            if tb.objectName() == "qt_toolbar_ext_button":  # (a QToolBarExtension)
                extension = _rect(tb) if tb.isVisible() else None
            elif tb.inherits("QToolButton") and tb.defaultAction() is not None:
                name = _command_name(tb.defaultAction())
                if tb.isVisible():
                    buttons[name] = _rect(tb) + [tb.isEnabled()]
                    shown.append(name)
                elif tb.defaultAction().isVisible():
                    hidden.append(name)
                if tb.menu() is not None:
                    groups[name] = list(_entries(tb.menu()))
                    disabled += [_command_name(a) for a in tb.menu().actions()
                                 if not a.isSeparator() and a.isVisible() and not a.isEnabled()]
                    if tb.menu().isVisible():
                        open_menus[name] = _entries(tb.menu())
        bars[bar.objectName()] = {"rect": _rect(bar), "buttons": shown, "hidden": extension is not None,
                                  "behind_extension": hidden, "extension": extension}
    menus = {}
    for a in mw.menuBar().actions():
        if a.menu() is not None and a.isVisible():
            title = a.text().replace("&", "")
            menus[title] = _rect(mw.menuBar(), mw.menuBar().actionGeometry(a))
            if a.menu().isVisible():
                open_menus[title] = _entries(a.menu())
    enabled = {_command_name(b): b.isEnabled() for a in mw.menuBar().actions() if a.menu() is not None
               for b in a.menu().actions() if not b.isSeparator()}  # (a shortcut does nothing while greyed)
    return {"bars": bars, "buttons": buttons, "groups": groups, "disabled": disabled, "menus": menus, "open": open_menus,
            "menu_enabled": enabled,
            "commands": [c for c in Gui.listCommands() if c.startswith("HapticSculpt_")]}


#: How much of the report view's text (its end) the state carries.
REPORT_CHARS = 6000


def _console_panels_and_questions():
    """Five things found in one walk of the main window's widgets: [x, y, width, height] on the
    screen of the Python console if it is shown (else None), of each shown panel FreeCAD lays over
    the 3D view (FreeCAD 1.1's Tasks panel on the view's right: a wheel turned over it does not reach
    the view, FreeCAD issue 21141; none before 1.0), and the buttons of a question FreeCAD shows (a
    QMessageBox: "Save all changes...?") by text, at their centres in screen pixels, the end of
    the report view's text (REPORT_CHARS), and what a shown file dialog's file name field holds
    (else None) with whether its completer's popup list is shown and where its buttons are."""
    console, panels, buttons, report, stack = None, [], {}, "", [(Gui.getMainWindow(), False, False)]
    file_name, file_buttons = None, {}
    while stack:
        w, in_box, in_files = stack.pop()
        name = w.metaObject().className()
        if w.objectName() == "fileNameEdit" and w.inherits("QLineEdit") and w.isVisible():
            # (Qt's own file dialog names its field so; the completer's popup is a window of its own)
            completer = w.completer()
            file_name = {"text": w.text(), "popup": bool(completer and completer.popup().isVisible())}
        if name == "Gui::DockWnd::ReportOutput":
            report = w.toPlainText()[-REPORT_CHARS:]
        if name == "Gui::OverlayTabWidget" and w.isVisible():
            panels.append(_rect(w))
        if console is None and name == "Gui::PythonConsole" and w.isVisible():
            console = _rect(w)
        in_box = in_box or (w.inherits("QMessageBox") and w.isVisible())
        in_files = in_files or (w.inherits("QFileDialog") and w.isVisible())
        if (in_box or in_files) and w.inherits("QPushButton") and w.isVisible() and w.text():
            centre, ratio = w.mapToGlobal(w.rect().center()), w.devicePixelRatioF()
            at = [round(centre.x() * ratio), round(centre.y() * ratio)]
            (buttons if in_box else file_buttons)[w.text().replace("&", "")] = at
        stack.extend((c, in_box, in_files) for c in w.children() if c.isWidgetType())
    if file_name is not None:
        file_name["buttons"] = file_buttons  # (the file dialog's own: Save, Cancel)
    return console, panels, buttons, report, file_name


def _focus():
    """The class of the widget that has the main window's keyboard focus."""
    w = Gui.getMainWindow().focusWidget()
    return w.metaObject().className() if w is not None else None


def _focus_is_field():
    """True if the keyboard is in a field a value is typed into (a name being edited in the tree)."""
    w = Gui.getMainWindow().focusWidget()
    return w is not None and bool(w.inherits("QLineEdit") or w.inherits("QAbstractSpinBox"))


def write(*_):
    state = {"version": [int(x) for x in FreeCAD.Version()[:2]],
             "workbench": Gui.activeWorkbench().name() if Gui.activeWorkbench() else "",
             "active": FreeCAD.ActiveDocument.Name if FreeCAD.ActiveDocument else None, "docs": {}, "views": _views(),
             "task_dialog": bool(Gui.Control.activeDialog()), "tree": _tree_items(),
             "task_buttons": _task_buttons(), "toolbars": _toolbars(),
             "focus": _focus(), "focus_field": _focus_is_field(), "selection": [[o.ObjectName, list(o.SubElementNames)]
                                              for o in Gui.Selection.getSelectionEx()],
             "preselection": _preselection(), "points": _probed_points()}
    (state["console"], state["overlay_panels"], state["message_buttons"], state["report"],
     state["file_dialog"]) = _console_panels_and_questions()
    for name, doc in FreeCAD.listDocuments().items():
        facts = _shape_facts(doc)
        state["docs"][name] = {"undo": list(doc.UndoNames), "redo": list(doc.RedoNames), "file": doc.FileName,
                               "modified": bool(getattr(doc, "isTouched", lambda: False)()),
                               "gui_modified": bool(getattr(Gui.getDocument(name), "Modified", False)),
                               "sculpts": _sculpts(doc), "objects": [o.Name for o in doc.Objects],
                               "solids": _solids(doc, facts), "features": _features(doc, facts),
                               "screen": {o.Name: _on_screen(o) for o in doc.Objects if hasattr(o, "Shape")},
                               "edge_points": {o.Name: _edge_points(o) for o in doc.Objects if hasattr(o, "Shape")}}
    try:
        import HapticSculpt.gui.workbench as hg
        ctl = hg.controller()
        state["painting"] = ctl.painting
        state["paint_dabs"] = len(ctl._paint_path) if ctl._paint_stroke is not None else 0  # (a held paint drag's)
        state["session"] = ctl.session is not None
        import HapticSculpt.gui as hgui
        state["recovery"] = {"pending": hgui.recovery.pending, "docs": hgui.recovery.written}
        state["inputs"] = len(ctl.inputs)
        state["mouse_point"] = None if ctl.mouse_point is None else [float(x) for x in ctl.mouse_point]
        state["overlays"] = [{"display": ov.display, "frames": ov.frames, "view_size": list(ov.view.getSize()),
                              "hud": ov.hud.boxes() if ov.hud is not None else {},
                              "status_text": getattr(ov, "status_text", ""),
                              "sliders": ov.panel.values(ov.obj) if ov.panel_visible else [],
                              "stripes": ov.stripes, "active_view": ov.view is getattr(Gui.ActiveDocument, "ActiveView", None),
                              "view": id(ov.view), "object": ov.obj.Name, "cursor": ov.cursor_shown,
                              "cursor_at": None if ov.cursor is None else [float(x) for x in ov.cursor[0]],
                              "surface_drawn": ov.surface_drawn, "offset": ov.offset(), "continuity": ov.continuity, "combs": ov.combs,
                              "neighbours_drawn": ov.neighbours_drawn,
                              "trimmed": any(v is not None for v in ov._trims.values()),
                              "continuity_worst": ov.continuity_worst,
                              "legend": [ov.legend[0], [float(x) for x in ov.legend[1]]]
                              if getattr(ov, "legend", None) else None,
                              "drawn": ov._root.getNumChildren() > 0}
                             for ov in ctl.overlays.values()]
    except Exception as exc:  # noqa: BLE001 - the workbench not loaded yet
        state["controller_error"] = str(exc)
    tmp = OUT + ".tmp"
    with open(tmp, "w") as f:
        f.write(json.dumps(state))  # (dumps encodes in C; dump to a file in Python, 10 times slower)
    os.replace(tmp, OUT)


_sensor = coin.SoTimerSensor(write, None)
_sensor.setInterval(coin.SbTime(0.1))
_sensor.schedule()
