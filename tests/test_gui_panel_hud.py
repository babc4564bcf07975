"""The slider panel and the HUD as a designer meets them: FreeCAD's real GUI under Xvfb, real X
input (xdotool). The panel's sliders (the material's, the curvature targets', the current tool's
settings) are dragged in the isometric and the front view, with and without a mouse session: each
drag changes its value as one undo step and never sculpts. The HUD
over white zebra stripes: its text stands on a dark backing, its items do not overlap, the zebra
legend shows as many bands as the display has stripes. Screenshots: build/screenshots/real_panel_*.png."""
from __future__ import annotations

import os
import time

import numpy as np
import pytest
from test_gui_real_input import NEEDS, SHOTS, Desktop, patch_with_keyed_constraints, sculpt, undo, view_direction

SLIDERS = [("mass", "Set mass"), ("damping", "Set damping"), ("stiffness", "Set stiffness"),
           ("bending", "Set bending"), ("pull", "Set pull"), ("curvature_u", "Set curvature"),
           ("curvature_v", "Set curvature"),
           # then the current tool's settings, as the core declares them (the rope's: a new patch's tool)
           *[(f"tool.rope.{name}", "Tool: rope") for name in ("stiffness", "stiff_stiffness", "threshold", "reel_time")]]
VIEW_KEYS = {"iso": "0", "front": "1", "top": "2"}  # FreeCAD's standard view shortcuts
pytestmark = pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD")


def overlay(s: dict) -> dict:
    return next(o for o in s["overlays"] if o["active_view"])


def camera(s: dict) -> str:
    return next(v for v in s["views"] if v["active"])["camera"]


#: Each standard view's direction, as a test on the active view's (iso: from above and aside).
VIEW_DIRECTIONS = {"iso": lambda v: -0.9 < v[2] < -0.3 and abs(v[0]) > 0.2 and abs(v[1]) > 0.2,
                   "front": lambda v: v[1] > 0.99, "top": lambda v: v[2] < -0.99}


def set_view(d: Desktop, name: str) -> None:
    """FreeCAD's key for the view ``name``, then waits for the view to look that way (it may do so
    already: a first patch is shown isometric)."""
    d.xdo("key", VIEW_KEYS[name])
    d.wait(lambda s: VIEW_DIRECTIONS[name](view_direction(s)), f"the {name} view")


def calibrate(d: Desktop) -> None:
    """Desktop.calibrate on the pixels the view's events give (the HUD's; FreeCAD 0.20's getCursorPos
    differed from them by 4 % and more), waiting for a state written after each move (the
    overlay's frame count is the clock), checked on a third point."""
    def cursor_at(x: int, y: int) -> list[float]:
        d.xdo("mousemove", str(x), str(y))
        frames = overlay(d.state())["frames"]
        s = d.wait(lambda s: overlay(s)["frames"] > frames + 12, "a state written after the move")
        return next(v for v in s["views"] if v["active"])["pixel"]

    # (screen points inside the 3D view of a 1280 x 1024 and of a 1000 x 720 window)
    (s0, v0), (s1, v1) = ((300, 220), cursor_at(300, 220)), ((700, 380), cursor_at(700, 380))
    d._map = [(s0[k], v0[k], (s1[k] - s0[k]) / (v1[k] - v0[k])) for k in (0, 1)]
    check = cursor_at(500, 300)
    assert max(abs(a - b) for a, b in zip(d.to_screen(check), (500, 300))) <= 2, (check, d._map)


def at_rest(d: Desktop, timeout: float = 60.0) -> np.ndarray:
    """Waits until the shown surface stays within 1e-4 mm over ten observer states (a session
    bends the patch toward curvature targets the sliders set before it ran); its poles then."""
    end, still, last = time.monotonic() + timeout, 0, None
    while still < 10:
        if time.monotonic() > end:
            raise AssertionError("the surface never came to rest")
        time.sleep(0.1)
        now = np.array(sculpt(d.state())["shape_poles"])
        still = still + 1 if last is not None and np.abs(now - last).max() < 1e-4 else 0
        last = now
    return last


def screen_box(d: Desktop, box: list[float]) -> tuple[int, int, int, int]:
    """A HUD box (view pixels, origin bottom-left) as screen rows and columns (r0, r1, c0, c1)."""
    (c0, r1), (c1, r0) = d.to_screen([box[0], box[1]]), d.to_screen([box[2], box[3]])
    return min(r0, r1), max(r0, r1), min(c0, c1), max(c0, c1)


def target(f: float) -> float:
    """Where a drag takes a knob at f: 0.15 of the track toward the middle (values a patch rests
    with: a light, stiff, hardly damped one, mass 0.06, stiffness 9500, damping 0.09, never did)."""
    return f + 0.15 if f < 0.5 else f - 0.15


def drag_slider(d: Desktop, k: int) -> None:
    """Drags slider k's knob from where it is to :func:`target`, as a hand does."""
    s = d.state()
    x0, y0, x1, y1 = overlay(s)["hud"][f"track{k + 1}"]
    f = overlay(s)["sliders"][k][3]
    to = target(f)
    y = (y0 + y1) / 2
    points = [d.to_screen([x0 + (f + (to - f) * t) * (x1 - x0), y]) for t in np.linspace(0, 1, 8)]
    d.drag(points, seconds=0.5)


def check_drag(d: Desktop, k: int, still: float | None, what: str) -> None:
    """Drags slider k: its value moves there as exactly one undo step, no stroke; ``still``: nor
    does the surface, by more than this many mm."""
    name, title = SLIDERS[k]
    poles = at_rest(d) if still is not None else None
    s = d.state()
    before, f = undo(s), overlay(s)["sliders"][k][3]
    drag_slider(d, k)
    d.wait(lambda s: undo(s)[0] == title and undo(s)[1:6] == before[:5] and not overlay(s)["sliders"][k][2],
           f"{title}: one undo step ({what})")
    time.sleep(0.5)  # (a second step would show by now)
    s = d.state()
    assert undo(s)[1:6] == before[:5], (what, undo(s), before)
    assert "Sculpt stroke" not in undo(s), (what, undo(s))
    moved = overlay(s)["sliders"][k][3]
    assert abs(moved - target(f)) < 0.03, (what, name, f, moved)
    if still is not None:
        change = np.abs(np.array(sculpt(s)["shape_poles"]) - poles).max()
        assert change < still, f"{name} ({what}) moved the surface by {change} mm"


def test_each_slider_drag_is_one_undo_step_and_never_a_stroke(tmp_path):
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.xdo("mousemove", "640", "500")
        patch_with_keyed_constraints(d)  # (the curvature constraint gives the curvature sliders a target)
        d.press_button("Panel", lambda s: "track6" in overlay(s)["hud"], "the slider panel")
        calibrate(d)
        # A mouse session (the left button sculpts there): a stroke would pull millimetres (the
        # issue's spike); a material slider moves the running patch by hundredths at most (10 times
        # less damping lets it settle further under its penalty constraints: 0.012 mm seen). A new
        # curvature target bends it (slowly, not a stroke), so those last and unmeasured.
        # Every slider is dragged with and without a session, in one of two views each time (each
        # view sees sliders of both kinds, with and without a session: a front view puts the patch
        # edge-on behind the panel, where a press went through to the patch once).
        d.press_button("Session", lambda s: sculpt(s)["session"], "a mouse session")
        for view, group in (("iso", (0, 2, 4, 5)), ("front", (1, 3, 6))):
            d.xdo("mousemove", "640", "500")
            set_view(d, view)
            for k in group:
                check_drag(d, k, 0.05 if k < 5 else None, f"{view} view, session")
            d.shot(f"panel_{view}_session")
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
        # without a session nothing moves the surface but a stroke (the tool's sliders too)
        for view, group in (("front", (0, 2, 4, 5, 7, 9)), ("iso", (1, 3, 6, 8, 10))):
            d.xdo("mousemove", "640", "500")
            set_view(d, view)
            for k in group:
                check_drag(d, k, 1e-6, f"{view} view")
            d.shot(f"panel_{view}_idle")
        # Shift held during the drag: the knob moves a tenth as far as the mouse (60 pixels took
        # stiffness from 100 to 2190); the mouse lets go before Shift does
        k = 2
        s = d.state()
        x0, y0, x1, y1 = overlay(s)["hud"][f"track{k + 1}"]
        f, before = overlay(s)["sliders"][k][3], undo(s)
        x, y = d.to_screen([x0 + f * (x1 - x0), (y0 + y1) / 2])
        def pixel(s: dict) -> float:  # (where the view's events have the mouse: the HUD's pixels)
            return next(v["pixel"] for v in s["views"] if v["active"])[0]

        d.xdo("mousemove", str(x), str(y))
        time.sleep(0.2)
        # (the press puts the knob under the mouse, as a click on a track does; where the view saw it,
        # not where the calibration aimed: 1.9 px off once under load, a tenth of the fine drag's reach)
        pressed = d.wait(lambda s: abs(pixel(s) - (x0 + f * (x1 - x0))) < 4, "the mouse on the knob")
        pressed = pixel(pressed)
        # (the last move one pixel long: under load the release was taken before the last move, and
        # the knob stopped 1.9 px short after a 21 px one; a lost 1 px move costs a tenth of a pixel)
        d.xdo("mousedown", "1", "keydown", "shift", "mousemove", str(x + 1), str(y))
        for dx in (20, 40, 60, 61):
            time.sleep(0.1)
            d.xdo("mousemove", str(x + dx), str(y))
        time.sleep(0.1)
        d.xdo("mouseup", "1", "keyup", "shift")
        s = d.wait(lambda s: undo(s)[0] == "Set stiffness" and undo(s)[1:6] == before[:5], "the fine drag's step")
        moved = overlay(s)["sliders"][k][3] - f
        width = x1 - x0
        expected = (pressed - (x0 + f * width)) / width + 60 / width / 10
        assert abs(moved - expected) < 0.008 and moved > 0.5 * 60 / width / 10, (f, moved, expected, 60 / width)
        assert sculpt(d.state())["strokes"] == 0
    finally:
        d.close()


@pytest.mark.parametrize("window", [(1280, 1024), (1000, 720)])
def test_the_hud_reads_over_white_zebra_stripes_and_its_legend_counts_the_stripes(tmp_path, window):
    d = Desktop(str(tmp_path), "CAD")
    try:
        if window != (1280, 1024):
            d.xdo("windowsize", "--sync", d.xdo("search", "--name", "FreeCAD").split()[-1], *map(str, window))
        d.xdo("mousemove", str(window[0] // 2), str(window[1] // 2))
        patch_with_keyed_constraints(d)  # jacks on the patch
        d.press_button("Panel", lambda s: "track6" in overlay(s)["hud"], "the slider panel")
        d.press_button("Zebra", lambda s: overlay(s)["display"] == "zebra", "zebra stripes")
        calibrate(d)
        set_view(d, "top")  # the flat patch faces the eye: its reflection lines are all white
        before = camera(d.state())
        d.xdo("key", "--delay", "150", "v", "f")  # fit all: the patch in the view's middle
        d.wait(lambda s: camera(s) != before, "fit all")
        # zoom in at the view's centre (ctrl++, View > Zoom in: the wheel zooms at the mouse, and
        # FreeCAD 1.1's Tasks panel lies over the view's right part, where a wheel does not reach it)
        # until the patch fills the view: white behind every HUD item
        for _ in range(40):
            s = d.state()
            w, h = overlay(s)["view_size"]
            centre, east, west, north, south = sculpt(s)["screen"]
            if west[0] < 0 and east[0] > w and south[1] < 0 and north[1] > h:
                break
            d.xdo("key", "ctrl+plus")
            d.wait(lambda s2: sculpt(s2)["screen"] != sculpt(s)["screen"], "the zoom")
        else:
            raise AssertionError("the patch never filled the view")
        for stripes in (6, 12, 24):
            for _ in range(3):
                if d.state()["overlays"] and overlay(d.state())["stripes"] == stripes:
                    break
                current = overlay(d.state())["stripes"]
                d.press_button("ZebraStripes", lambda s: overlay(s)["stripes"] != current, "the stripe count")
            s = d.wait(lambda s: overlay(s)["stripes"] == stripes and "legend_bar" in overlay(s)["hud"], "the legend")
            drawn = overlay(s)["frames"]  # (the frames after the change drawn, not merely queued)
            d.wait(lambda s: overlay(s)["frames"] >= drawn + 2, "two frames after the change")
            img = d.shot(f"panel_zebra_{window[0]}_{stripes}")
            boxes = overlay(d.state())["hud"]
            luminance = img.mean(axis=2)
            # the legend: as many black and white bands as the display has stripes, counted as its
            # white bands (half of them) down a column through the whole bar and the dark backing
            # around it (a few pixels each way: the box maps to the screen to within a pixel or two,
            # and a small window's bands are only 3 px high)
            r0, r1, c0, c1 = screen_box(d, boxes["legend_bar"])
            column = luminance[r0 - 3:r1 + 3, (c0 + c1) // 2] > 0.5
            white = int(np.count_nonzero(column[1:] & ~column[:-1])) + int(column[0])
            assert 2 * white == stripes, f"the legend shows {white} white bands for {stripes} stripes"
            # no two items overlap, nor two backings
            items = {k: b for k, b in boxes.items() if not k.startswith("back_")}
            for group in (items, {k: b for k, b in boxes.items() if k.startswith("back_")}):
                names = sorted(group)
                for i, a in enumerate(names):
                    for b in names[i + 1:]:
                        (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = group[a], group[b]
                        assert ax1 <= bx0 or bx1 <= ax0 or ay1 <= by0 or by1 <= ay0, f"{a} overlaps {b}"
            # every text reads: bright glyphs on a dark ground, with white stripes all around the backing
            for name in [k for k in items if k.startswith(("slider", "status", "legend_title"))]:
                r0, r1, c0, c1 = screen_box(d, items[name])
                patch = luminance[r0:r1, c0:c1]
                assert np.percentile(patch, 50) < 0.4 and patch.max() > 0.85, (name, np.percentile(patch, 50), patch.max())
                text, ground = _linear(patch.max()), _linear(np.percentile(patch, 50))
                assert (text + 0.05) / (ground + 0.05) > 4.5, f"{name}: contrast {(text + 0.05) / (ground + 0.05):.1f}"
            for back in ("back_sliders", "back_legend", "back_status"):
                r0, r1, c0, c1 = screen_box(d, boxes[back])
                ring = np.concatenate([luminance[r0 - 6:r0 - 2, c0:c1].ravel(), luminance[r1 + 2:r1 + 6, c0:c1].ravel()])
                inside = img[r0 + 1:r1 - 1, c0 + 1:c1 - 1]
                red, green, blue = inside[..., 0], inside[..., 1], inside[..., 2]
                assert not np.any((red > 0.8) & (green < 0.3) & (blue < 0.3)), f"a point jack over {back}"
                if back == "back_sliders":
                    assert np.mean(ring > 0.9) > 0.5, "the test's premise: white stripes around the slider panel"
    finally:
        d.close()


def _linear(srgb: float) -> float:
    """Relative luminance of an sRGB grey (WCAG)."""
    return srgb / 12.92 if srgb <= 0.04045 else ((srgb + 0.055) / 1.055) ** 2.4


os.makedirs(SHOTS, exist_ok=True)


def test_a_material_slider_scales_a_painted_map(tmp_path):
    """Stiffness painted along a line, then its slider dragged: the map is scaled to the slider's
    new mean, the painted line kept (the slider set one value everywhere and wiped it)."""
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.xdo("mousemove", "640", "500")
        s = d.new_patch()
        d.press_button("Panel", lambda s: "track3" in overlay(s)["hud"], "the slider panel")
        calibrate(d)  # (on the overlay's frames: the panel draws them)
        centre, east, west, _, _ = [d.to_screen(p) for p in sculpt(s)["screen"]]
        d.press_button("PaintStiffness", lambda s: s["painting"] == "stiffness", "the airbrush")
        d.drag([west, ((west[0] + centre[0]) // 2, (west[1] + centre[1]) // 2), east], seconds=0.3)
        s = d.wait(lambda s: undo(s)[0] == "Paint stiffness", "the painted line")
        lo, hi, n = sculpt(s)["stiffness_map"]
        assert n > 1 and hi > 2 * lo, (lo, hi, n)
        d.press_button("PaintStiffness", lambda s: s["painting"] is None, "the airbrush off")
        mean = overlay(d.state())["sliders"][2][1]
        drag_slider(d, 2)
        s = d.wait(lambda s: undo(s)[0] == "Set stiffness" and not overlay(s)["sliders"][2][2], "the slider's step")
        lo2, hi2, n2 = sculpt(s)["stiffness_map"]
        factor = overlay(s)["sliders"][2][1] / mean
        assert abs(factor - 1) > 0.5, factor  # (the drag moved the mean)
        assert n2 == n and abs(lo2 / lo - factor) < 0.01 * factor and abs(hi2 / hi - factor) < 0.01 * factor, \
            ((lo, hi, n), (lo2, hi2, n2), factor)
        # a drag from the panel's backing (a slider's text, off its track) in a mouse session is the
        # panel's: no stroke (it went through and sculpted the patch)
        d.press_button("Session", lambda s: sculpt(s)["session"], "a mouse session")
        x0, y0, x1, y1 = overlay(d.state())["hud"]["slider1"]
        start = d.to_screen([(x0 + x1) / 2, (y0 + y1) / 2])
        before = undo(d.state())
        d.drag([start] + [(start[0] + 25 * k, start[1] + 25 * k) for k in range(1, 12)], seconds=0.6)
        assert d.wait_still(undo, "the drag's aftermath") == before
        assert sculpt(d.state())["strokes"] == 0
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
    finally:
        d.close()
