"""The GUI layer's pure parts, without FreeCAD: the displays kept with a file (read back only where
well-formed, written only on a change) and the HUD's line for a session's last stroke."""
from __future__ import annotations

import json
from types import SimpleNamespace

import pytest
from HapticSculpt.gui import kept_displays
from HapticSculpt.gui.overlay import stroke_text


class FakeViewObject:
    """The parts of a FreeCAD view provider kept_displays uses: properties added, set and read."""

    def __init__(self) -> None:
        self.PropertiesList: list[str] = []
        self.writes = 0
        self.modes: dict[str, int] = {}

    def addProperty(self, kind: str, name: str, group: str, doc: str) -> None:
        assert kind == "App::PropertyString"
        self.PropertiesList.append(name)
        object.__setattr__(self, name, "")

    def setEditorMode(self, name: str, mode: int) -> None:
        self.modes[name] = mode

    def __setattr__(self, name: str, value) -> None:
        if name == kept_displays.PROPERTY:
            self.writes += 1
        object.__setattr__(self, name, value)


def sculpt(restoring: bool = False) -> SimpleNamespace:
    return SimpleNamespace(ViewObject=FakeViewObject(), Document=SimpleNamespace(Restoring=restoring))


def overlay_like(**changes) -> SimpleNamespace:
    values = {"display": "shading", "combs": False, "continuity": False, "panel_visible": False,
              "stripe_mode": "reflection", "stripes": 12.0, "stripe_angle": 0.0, "stripe_direction": (0.0, 0.0, 1.0),
              "comb_every": 4, "comb_gain": 1.0}
    values.update(changes)
    return SimpleNamespace(**values)


def test_displays_round_trip_and_are_written_only_when_they_change():
    obj = sculpt()
    default = kept_displays.settings_of(overlay_like())
    kept_displays.keep(obj, default, default)
    assert kept_displays.PROPERTY not in obj.ViewObject.PropertiesList, "a sculpt that showed nothing gained a property"
    shown = kept_displays.settings_of(overlay_like(display="zebra", combs=True, stripes=24.0,
                                                   stripe_direction=(1.0, 0.0, 0.0)))
    kept_displays.keep(obj, shown, default)
    kept_displays.keep(obj, shown, default)
    assert obj.ViewObject.writes == 1 and obj.ViewObject.modes[kept_displays.PROPERTY] == 2
    back = kept_displays.kept(obj)
    assert back["display"] == "zebra" and back["combs"] is True and back["stripes"] == 24.0
    assert back["stripe_direction"] == (1.0, 0.0, 0.0)


def test_a_file_being_read_is_not_written():
    obj = sculpt(restoring=True)
    default = kept_displays.settings_of(overlay_like())
    kept_displays.keep(obj, kept_displays.settings_of(overlay_like(display="mean")), default)
    assert kept_displays.PROPERTY not in obj.ViewObject.PropertiesList


@pytest.mark.parametrize("text", ["", "not json", "[1, 2]", "null",
                                  json.dumps({"display": 3, "combs": "yes", "stripes": True, "comb_every": 2.5,
                                              "stripe_direction": [1, 2], "unknown": 1})])
def test_malformed_kept_displays_are_ignored(text):
    obj = sculpt()
    obj.ViewObject.addProperty("App::PropertyString", kept_displays.PROPERTY, "HapticSculpt", "")
    setattr(obj.ViewObject, kept_displays.PROPERTY, text)
    assert kept_displays.kept(obj) == {}


def test_no_view_object_keeps_nothing():
    obj = SimpleNamespace(Document=SimpleNamespace(Restoring=False))  # (console mode: no view provider)
    kept_displays.keep(obj, {"display": "zebra"}, {})
    assert kept_displays.kept(obj) == {}


def test_the_last_strokes_line_says_why_it_barely_moved():
    def line(moved: float, pulled: float, stiffness: float = 100.0, held: int = 0, curves: int = 0) -> str:
        return stroke_text({"moved_mm": moved, "pulled_mm": pulled, "stiffness": stiffness, "held": held,
                            "curves": curves})
    assert line(0.034, 23.0, 95000.0, 28) == ("last stroke moved it 0.034 mm of a 23 mm pull: stiffness 95000 holds "
                                              "it, lower it in the slider panel")
    assert "held poles pin it there (Hold edges, P)" in line(0.75, 30.0, held=100)
    # a stroke beside a followed curve (a new designer was told of held poles only)
    assert ": the curves it follows and held poles pin it there (Follow curve: off, Hold edges, P)" in \
        line(0.0033, 23.0, held=28, curves=1)
    assert line(0.75, 30.0) == "last stroke moved it 0.75 mm of a 30 mm pull: the material is heavy or damped (slider panel)"
    assert line(12.0, 23.0, 95000.0) == "last stroke moved it 12 mm"
    # a pull the frames did not see (console mode, or a grab between two frames) gives no reason
    assert line(0.01, 0.0, 95000.0) == "last stroke moved it 0.01 mm"


def test_a_status_part_longer_than_the_hud_wraps_between_its_words():
    from HapticSculpt.gui.hud import _wrap
    reason = "last stroke moved it 0.032 mm of a 17 mm pull: stiffness 100000 holds it, lower it in the slider panel"
    lines = _wrap("tool: rope  |  clay  |  " + reason, 60)
    assert all(len(line) <= 60 for line in lines), lines
    assert lines[0] == "tool: rope  |  clay" and " ".join(lines[1:]) == reason
    assert _wrap("a  |  b", 60) == ["a  |  b"]
