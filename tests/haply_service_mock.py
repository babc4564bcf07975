"""A mock Haply Inverse Service for the Python tests: a WebSocket server on loopback (Debian's
python3-websockets) speaking the simulation channel's JSON as Haply documents it: the inventory on
connecting, then one state update per message received. Behind it an Inverse3 emulated as a grip
of mass m with damping, held by a hand that follows a script, driven by each command's
set_cursor_force (one 1 ms step per command), and a Verse Grip whose button follows the script.
(The C++ tests have their own, native_core/tests/haply_mock_service.hpp.)"""
from __future__ import annotations

import asyncio
import json
import threading

import numpy as np

REST = np.array([0.0, -0.12, 0.15])  # m: the cursor at rest in Haply's example inventory


class MockInverseService:
    """``script``: rows of (t, dx, dy, dz, button) around REST (m, Haply's frame: x right, y away
    from the user, z up). Use as a context manager; ``address`` is its "host:port"."""

    def __init__(self, script=((0.0, 0.0, 0.0, 0.0, 0),), devices=("049D",), in_use=False):
        self.script = [tuple(map(float, r)) for r in script]
        self.devices, self.in_use = list(devices), in_use
        self.tip, self.velocity, self.time = REST + np.array(self.script[0][1:4]), np.zeros(3), 0.0
        self.commands, self.largest_force, self.first_command = 0, 0.0, None
        self._loop = asyncio.new_event_loop()
        self._ready = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def __enter__(self) -> "MockInverseService":
        self._thread.start()
        assert self._ready.wait(10), "the mock service did not start"
        return self

    def __exit__(self, *exc) -> None:
        self._loop.call_soon_threadsafe(self._stop.set_result, None)
        self._thread.join(10)

    @property
    def address(self) -> str:
        return f"127.0.0.1:{self.port}"

    def _hand(self):
        rows = self.script
        k = max(i for i, r in enumerate(rows) if r[0] <= self.time or i == 0)
        if k + 1 >= len(rows):
            return REST + np.array(rows[k][1:4]), int(rows[k][4])
        a, b = rows[k], rows[k + 1]
        s = (self.time - a[0]) / (b[0] - a[0])
        return REST + np.array(a[1:4]) + s * (np.array(b[1:4]) - np.array(a[1:4])), int(a[4])

    def _step(self, force) -> None:
        hand, _ = self._hand()
        f = np.array(force) + 300.0 * (hand - self.tip) - 4.0 * self.velocity
        self.largest_force = max(self.largest_force, float(np.linalg.norm(force)))
        self.velocity += 1e-3 * f / 0.2
        self.tip += 1e-3 * self.velocity
        self.time += 1e-3

    def _message(self, inventory: bool) -> str:
        vec = lambda v: {"x": float(v[0]), "y": float(v[1]), "z": float(v[2])}  # noqa: E731
        entries = []
        for d in self.devices:
            e = {"device_id": d, "state": {"cursor_position": vec(self.tip), "cursor_velocity": vec(self.velocity)},
                 "status": {"calibrated": True, "in_use": self.in_use, "ready": True, "started": True}}
            if inventory:
                e["config"] = {"type": "inverse3", "handedness": "right"}
            entries.append(e)
        out = {"inverse3": entries,
               "verse_grip": [{"device_id": "61548", "state": {"button": bool(self._hand()[1]), "hall": 0}}]}
        if inventory:
            out["session_id"] = 7
        return json.dumps(out)

    async def _serve(self, ws, *_):
        await ws.send(self._message(True))
        async for text in ws:
            message = json.loads(text)
            if self.first_command is None:
                self.first_command = message
            self.commands += 1
            force = (0.0, 0.0, 0.0)
            for d in message.get("inverse3", []):
                v = d.get("commands", {}).get("set_cursor_force", {}).get("vector")
                if v:
                    force = (v["x"], v["y"], v["z"])
            self._step(force)
            await ws.send(self._message(False))

    def _run(self) -> None:
        import websockets

        async def main():
            self._stop = self._loop.create_future()
            async with websockets.serve(self._serve, "127.0.0.1", 0) as server:
                self.port = next(iter(server.sockets)).getsockname()[1]
                self._ready.set()
                await self._stop

        self._loop.run_until_complete(main())
