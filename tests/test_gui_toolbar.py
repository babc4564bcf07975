"""The workbench's toolbars as a designer first meets them: FreeCAD's real GUI at 1280 x 800 under
Xvfb, FreeCAD's default layout. Every command can be reached (a shown toolbar button, or an entry
of a drop-down opened with a real click), no toolbar hides buttons behind "»", a drop-down's button
repeats its entry picked last, no two commands show the same icon (compared as FreeCAD draws them,
in its menu), and Export STEP stays shown when the window is narrowed to 1000 px and to 800 px (where
our toolbars hide buttons behind "»"). Screenshots go to build/screenshots/real_toolbar*.png."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from test_gui_real_input import NEEDS, Desktop, sculpt, undo

WIDTH, HEIGHT = 1280, 800
#: Two icons are "the same picture" when their grey levels, each normalised to zero mean and unit
#: spread, correlate above this (disabled entries are drawn washed out: colour alone does not count).
SAME_PICTURE = 0.9


def _icon(img: np.ndarray, entry: list[int]) -> np.ndarray:
    """The picture inside a menu entry's icon (the icon: what differs from the menu's background,
    taken at the entry's right end, in the square at its left end; its middle 12 x 12 pixels, inside
    the tile's edge every icon shares), in grey levels normalised to zero mean and unit spread."""
    x, y, w, h = entry
    square = img[y + 1:y + h - 1, x + 2:x + h]  # (not the menu's frame)
    ys, xs = np.nonzero(np.abs(square - img[y + h // 2, x + w - 3]).max(axis=2) > 0.1)
    cy, cx = (ys.min() + ys.max() + 1) // 2, (xs.min() + xs.max() + 1) // 2
    grey = square[cy - 6:cy + 6, cx - 6:cx + 6].mean(axis=2)
    return (grey - grey.mean()) / (grey.std() + 1e-9)


def _drawn(img: np.ndarray, entry: list[int]) -> bool:
    """Whether a menu entry's icon square shows anything but the menu's background."""
    x, y, w, h = entry
    return bool((np.abs(img[y + 1:y + h - 1, x + 2:x + h] - img[y + h // 2, x + w - 3]).max(axis=2) > 0.1).any())


def _opened(d: Desktop, menu: str) -> dict[str, list[int]]:
    """The entries of a drop-down or menu once the observer sees it open, by command name."""
    return d.wait(lambda s: s["toolbars"]["open"][menu] and all(s["toolbars"]["open"][menu].values()),
                  f"{menu} open")["toolbars"]["open"][menu]


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick's import and FreeCAD")
def test_every_command_reachable_and_every_icon_distinct(tmp_path):
    d = Desktop(str(tmp_path), "CAD", screen=f"{WIDTH}x{HEIGHT}")
    try:
        s = d.new_patch()
        d.calibrate()
        centre = d.to_screen(sculpt(s)["screen"][0])
        d.xdo("mousemove", str(centre[0]), str(centre[1]), "click", "1")  # (selected: Output's commands run)
        d.wait(lambda s: sculpt(s)["selected"], "the patch selected")
        s = d.wait(lambda s: all(s["toolbars"]["buttons"][g][4] for g in s["toolbars"]["groups"]
                                 if g.startswith("HapticSculpt_")), "the drop-downs enabled", 30)
        d.shot("toolbar")
        bars = s["toolbars"]["bars"]
        ours = [name for name in bars if name.startswith("HapticSculpt")]
        assert ours == ["HapticSculpt create", "HapticSculpt output", "HapticSculpt sculpt", "HapticSculpt tools",
                        "HapticSculpt analysis"]
        assert not [name for name, bar in bars.items() if bar["hidden"]], "a toolbar hides buttons behind »"
        buttons = {n: b for n, b in s["toolbars"]["buttons"].items() if n.startswith("HapticSculpt_")}
        for name, (x, y, w, h, _) in buttons.items():
            assert 0 <= x and x + w <= WIDTH and 0 <= y and y + h <= HEIGHT, (name, x, y, w, h)
        assert "HapticSculpt_OutputGroup" in buttons and "HapticSculpt_ConstraintGroup" in buttons

        # Each drop-down opened with a real click on its arrow: its entries are where a click finds them.
        reached = set(buttons)
        groups = [g for g in s["toolbars"]["groups"] if g.startswith("HapticSculpt_")]
        for group in groups:
            x, y, w, h, _ = buttons[group]
            d.xdo("mousemove", str(x + w - 5), str(y + h // 2), "click", "1")
            entries = _opened(d, group)
            d.shot(f"toolbar_{group.removeprefix('HapticSculpt_')}")
            for name, (ex, ey, ew, eh) in entries.items():
                assert 0 <= ex and ex + ew <= WIDTH and 0 <= ey and ey + eh <= HEIGHT, (group, name)
            reached |= set(entries)
            d.xdo("key", "Escape")
            d.wait(lambda s: group not in s["toolbars"]["open"], f"the drop-down {group} closed")
        assert set(s["toolbars"]["commands"]) <= reached, set(s["toolbars"]["commands"]) - reached

        # A drop-down's entry runs its command, and the group's button runs it again from then on.
        d.press_button("ToolMagnet", lambda s: undo(s)[0] == "Tool: magnet", "Tool: magnet from the drop-down")
        d.press_button("ToolRope", lambda s: undo(s)[0] == "Tool: rope", "Tool: rope from the drop-down")
        d.press_button("Material", lambda s: undo(s)[0] == "Material: elastic", "elastic from the drop-down")
        x, y, w, h, _ = buttons["HapticSculpt_MaterialGroup"]
        d.xdo("mousemove", str(x + (w - 12) // 2), str(y + h // 2), "click", "1")  # (the button, not its arrow)
        d.wait(lambda s: undo(s)[:2] == ["Material: clay", "Material: elastic"], "clay from the group's button")

        # The menu lists every command with its icon: all of them side by side, at one size.
        x, y, w, h = s["toolbars"]["menus"]["HapticSculpt"]
        d.xdo("mousemove", str(x + w // 2), str(y + h // 2), "click", "1")
        menu = _opened(d, "HapticSculpt")
        commands = set(s["toolbars"]["commands"]) - set(groups)
        assert commands <= set(menu), commands - set(menu)
        # (open in Qt's state is not yet painted: under load the menu's icons reach the screen later)
        img = d.shot_showing("toolbar_menu", lambda img: all(_drawn(img, menu[name]) for name in commands),
                             "every entry's icon in the menu")
        d.xdo("key", "Escape")
        icons = {name: _icon(img, menu[name]) for name in commands}
        same = [(a, b, float((icons[a] * icons[b]).mean())) for a, b in itertools.combinations(sorted(icons), 2)]
        closest = max(same, key=lambda t: t[2])
        print(f"{len(icons)} icons; the most alike: {closest[0]} and {closest[1]}, correlation {closest[2]:.3f}")
        assert closest[2] < SAME_PICTURE, [t for t in same if t[2] >= SAME_PICTURE]

        # The window made narrower (Qt does not wrap the toolbars again): at 1000 px, and at 800 px,
        # where the toolbars no longer fit and buttons go behind "»" (at 1000 px FreeCAD 0.20's do,
        # 1.0's own toolbars are narrower and still fit); Export STEP's button stays shown. (Laid out:
        # every toolbar ends inside the window, to within the 2 px of the observer's rounding of Qt's
        # units to the screen's pixels: 0.20's last one ends at 1001.)
        name = d.xdo("search", "--name", "FreeCAD").split()[-1]
        for width, squeezed in ((1000, False), (800, True)):
            d.xdo("windowsize", "--sync", name, str(width), "720")
            s = d.wait(lambda s: all(b["rect"][0] + b["rect"][2] <= width + 2 for b in s["toolbars"]["bars"].values())
                       and (not squeezed or any(b["hidden"] for n, b in s["toolbars"]["bars"].items()
                                                if n.startswith("HapticSculpt"))),
                       f"the toolbars laid out in {width} px" + (", ours with buttons behind »" if squeezed else ""))
            d.shot(f"toolbar_narrow_{width}")
            assert "HapticSculpt_OutputGroup" in s["toolbars"]["buttons"], s["toolbars"]["bars"]
            x, y, w, h, _ = s["toolbars"]["buttons"]["HapticSculpt_OutputGroup"]
            assert x + w <= width, (width, x, w)
    finally:
        d.close()
