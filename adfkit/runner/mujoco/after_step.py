"""What acts after each MuJoCo physics step, as AMBF's vehicles and resistance sensors act after
each of Bullet's (vehicles.py, resist.py): the wrenches one step leaves are pushed onto
``xfrc_applied`` for the next step only, on top of the forces the control step set there."""

from __future__ import annotations


class AfterStep:
    """The wrenches ``_pending`` ((MuJoCo body id, wrench about its COM, world frame)) the last
    physics step left, pushed before the next and taken off after it."""

    def __init__(self, world) -> None:
        self.world = world
        self._pending: list[tuple] = []
        self._saved: list[tuple] = []

    def push(self) -> None:
        """Before a physics step: the wrenches the last one left, on top of the step's forces."""
        xf = self.world.data.xfrc_applied
        self._saved = [(bid, xf[bid].copy()) for bid, _ in self._pending]
        for bid, wrench in self._pending:
            xf[bid] += wrench

    def pull(self) -> None:
        """After the physics step: the forces as they were before push."""
        xf = self.world.data.xfrc_applied
        for bid, row in self._saved:
            xf[bid] = row
        self._saved = []
