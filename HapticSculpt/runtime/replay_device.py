"""A device that plays back a recorded or scripted cursor trajectory.

Positions are interpolated linearly between samples, orientations by normalised linear
interpolation of the quaternions (sign-aligned), buttons are held from the last sample; the
interpolation is the core's (native_core/src/devices/replay_device.cpp), shared with the threaded loops. The text
format (one sample per line: ``t x y z qw qx qy qz buttons``, floats written with 17 significant
digits) round-trips bit for bit, so any session recorded into it replays exactly.
"""
from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

HEADER = "# HapticSculpt trajectory v1: t x y z qw qx qy qz buttons"


def _numbers(name: str, value: Any, dtype: Any = float) -> np.ndarray:
    """`value` as an array, or a ValueError naming the argument (ragged or non-numeric input)."""
    try:
        return np.array(value, dtype=dtype)
    except (ValueError, TypeError, OverflowError) as exc:
        raise ValueError(f"{name}: expected numbers in a regular array ({exc})") from exc


@dataclass(frozen=True)
class CursorSample:
    """Cursor state at one instant: position (mm), orientation (w, x, y, z), button bit mask."""

    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    buttons: int

    @property
    def grab(self) -> bool:
        """Button 1 held."""
        return bool(self.buttons & 1)


class ReplayDevice:
    """Plays a trajectory: timestamps (s, strictly increasing), positions (n, 3) in mm, optional
    orientations (n, 4) as (w, x, y, z) quaternions and button bit masks (bit 0 = button 1 = grab).

    Without ``buttons`` button 1 is held for the whole trajectory except its last sample, so a
    scripted stroke grabs at the start and releases at the end.
    """

    capabilities = {"dof": 6, "force_output": False, "rate_hz": None}

    def __init__(self, t: Sequence[float], xyz: Sequence[Sequence[float]],
                 quat: Sequence[Sequence[float]] | None = None, buttons: Sequence[int] | None = None) -> None:
        times = _numbers("t", t)
        if times.ndim != 1 or times.size < 1:
            raise ValueError("t: expected a non-empty 1-D sequence of timestamps")
        if not np.all(np.isfinite(times)):
            raise ValueError("t: timestamps must be finite")
        if times.size > 1 and not np.all(np.diff(times) > 0):
            raise ValueError("t: timestamps must be strictly increasing")
        n = times.size
        pos = _numbers("xyz", xyz)
        if pos.shape != (n, 3):
            raise ValueError(f"xyz: expected shape ({n}, 3), got {pos.shape}")
        if not np.all(np.isfinite(pos)):
            raise ValueError("xyz: positions must be finite")
        if quat is None:
            q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
        else:
            q = _numbers("quat", quat)
            if q.shape != (n, 4):
                raise ValueError(f"quat: expected shape ({n}, 4), got {q.shape}")
            if not np.all(np.isfinite(q)):
                raise ValueError("quat: orientations must be finite")
            norms = np.linalg.norm(q, axis=1)
            if not np.all(norms > 1e-12):
                raise ValueError("quat: orientations must be non-zero quaternions")
            off = np.abs(norms - 1.0) > 1e-12  # leave unit quaternions bit-exact (file round trip)
            q[off] = q[off] / norms[off, None]
        if buttons is None:
            b = np.ones(n, dtype=np.int64)
            b[-1] = 0
        else:
            b = _numbers("buttons", buttons, None)
            if b.shape != (n,):
                raise ValueError(f"buttons: expected {n} button masks, got shape {b.shape}")
            if not np.issubdtype(b.dtype, np.integer) and not np.issubdtype(b.dtype, np.bool_):
                if not np.all(np.isfinite(b.astype(float))) or not np.all(b == np.round(b)):
                    raise ValueError("buttons: expected integer bit masks")
            b = b.astype(np.int64)
            if np.any(b < 0) or np.any(b > 0xFFFFFFFF):
                raise ValueError("buttons: bit masks must be in 0..2**32-1")
        self._t, self._xyz, self._q, self._buttons = times, pos, q, b
        self._sampler: Any = None  # native sampler, made on first use

    @property
    def duration(self) -> float:
        """Time of the last sample (s)."""
        return float(self._t[-1])

    @property
    def samples(self) -> int:
        """Number of recorded samples."""
        return int(self._t.size)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Copies of (t, xyz, quat, buttons)."""
        return self._t.copy(), self._xyz.copy(), self._q.copy(), self._buttons.copy()

    @property
    def native(self) -> Any:
        """A fresh C++ replay of this trajectory (what sessions run; one per session, since it keeps a
        position hint)."""
        from ..core import native as _core
        return _core.NativeReplayDevice(self._t.tolist(), self._xyz, self._q, self._buttons.astype(np.uint32).tolist())

    def sample(self, time: float) -> CursorSample:
        """The cursor at ``time`` (clamped to the trajectory's ends), by the same C++ code the
        threaded loops run."""
        if self._sampler is None:
            self._sampler = self.native
        s = self._sampler.sample(float(time))
        return CursorSample(tuple(map(float, s["position"])), tuple(s["orientation"]), int(s["buttons"]))

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the trajectory in the text format (exact round trip)."""
        data = np.column_stack([self._t, self._xyz, self._q, self._buttons.astype(float)])
        np.savetxt(path, data, fmt=["%.17g"] * 8 + ["%d"], header=HEADER[2:], comments="# ")

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> "ReplayDevice":
        """Read a trajectory written by :meth:`save` (or by a recorded session)."""
        try:
            with warnings.catch_warnings():  # an empty file: refused below with the column check
                warnings.simplefilter("ignore", UserWarning)
                data = np.loadtxt(path, ndmin=2, dtype=float)
        except ValueError as exc:
            raise ValueError(f"path: {os.fspath(path)!r} is not a trajectory file ({exc})") from exc
        if data.ndim != 2 or data.shape[1] != 9:
            raise ValueError(f"path: {os.fspath(path)!r}: expected 9 columns (t x y z qw qx qy qz buttons)")
        return cls(data[:, 0], data[:, 1:4], data[:, 4:8], data[:, 8].astype(np.int64))

    @classmethod
    def stroke(cls, start: Sequence[float], end: Sequence[float], seconds: float = 1.0,
               hold: float = 0.0, samples: int = 50) -> "ReplayDevice":
        """A straight grab-drag-release stroke from ``start`` to ``end`` over ``seconds``, then
        ``hold`` seconds held still at ``end`` before the release."""
        if not (seconds > 0 and np.isfinite(seconds)):
            raise ValueError("seconds: must be finite and > 0")
        if not (hold >= 0 and np.isfinite(hold)):
            raise ValueError("hold: must be finite and >= 0")
        if samples < 2:
            raise ValueError("samples: need at least 2")
        a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
        s = np.linspace(0.0, 1.0, samples)
        t = s * seconds
        xyz = a + s[:, None] * (b - a)
        if hold > 0:
            t = np.append(t, seconds + hold)
            xyz = np.vstack([xyz, b])
        buttons = np.ones(t.size, dtype=np.int64)
        buttons[-1] = 0
        return cls(t, xyz, None, buttons)
