"""Instability caught while a world plays, in either engine: never a silent reset.

An engine that blows up does not always leave a trace at the end of a run: MuJoCo meets NaN or
a huge value in its state, warns, and resets the whole state to the model's initial pose (a
PSM jumps home, and a check at the end sees a calm scene); PyBullet carries NaN on, or flings a
body off at hundreds of metres a second before it settles somewhere. So each world watches
while it steps and keeps every event, with the simulated time and the body, for the report,
``metrics.json`` and Gymnasium's ``info``; any event makes the run unstable.

Each engine's watch lives with its back end (``pybullet/stability.py``, ``mujoco/stability.py``);
this module holds what they share: the event, the watch and the thresholds.

- MuJoCo: its warning counters (``MjData.warning``) for NaN/Inf/huge values in the positions,
  velocities and accelerations (after which MuJoCo resets the state) and for a singular
  inertia, read at every control step through MuJoCo's warning callback, which this module
  installs once per process (it also keeps MuJoCo from writing ``MUJOCO_LOG.TXT`` into the
  current folder: the messages go into the report instead).
- PyBullet: every dynamic body's position and velocity every ``CHECK_EVERY_S`` of simulated
  time: NaN or Inf, or a speed above ``FLUNG_SPEED``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

#: Simulated seconds between two PyBullet checks (each reads every dynamic body's state once).
CHECK_EVERY_S = 0.02
#: A body faster than this (m/s) has been flung by the solver: nothing in a surgical scene moves so.
FLUNG_SPEED = 100.0
#: Events kept per world (the first ones say what went wrong; the rest are counted).
MAX_EVENTS = 50


@dataclass
class Instability:
    time_s: float
    body: str | None
    kind: str  # "state-reset" (MuJoCo), "singular-inertia" (MuJoCo), "nan", "flung"
    message: str

    def as_dict(self) -> dict:
        return asdict(self)

    def __str__(self) -> str:
        who = f" ({self.body})" if self.body else ""
        return f"t = {self.time_s:.3f} s{who}: {self.message}"


class Watch:
    """The events of one world, in order."""

    def __init__(self) -> None:
        self.events: list[Instability] = []
        self.dropped = 0

    def add(self, event: Instability) -> None:
        if len(self.events) < MAX_EVENTS:
            self.events.append(event)
        else:
            self.dropped += 1

    def report(self) -> dict:
        return {
            "instabilities": [e.as_dict() for e in self.events],
            **({"instabilities_not_listed": self.dropped} if self.dropped else {}),
        }
