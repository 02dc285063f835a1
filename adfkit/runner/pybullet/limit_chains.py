"""AMBF's hinge and slider stops on a free multibody in PyBullet (which and when: runner/
free_stops.py): while the chain step plays a multibody, every joint's motor is driven at the
velocity AMBF's solver leaves it at (force up to joint_commands.LIMIT_FORCE), the joints' PyBullet
limits opened meanwhile and limit_rows.py leaving them alone; given back, the joints' limits and
rows are theirs again and their motors off (but those a command drives since). The world steps
physics steps one by one when there is such a multibody (world.py)."""

from __future__ import annotations

import pybullet as pb

from ..free_stops import FreeStops
from ..joint_commands import LIMIT_FORCE

#: how far out a joint's PyBullet limits are opened while the chain step plays it (rad or m)
OPEN = 1e3


class LimitChains(FreeStops):
    def before_step(self) -> None:
        """Before each physics step: the joints of the multibodies the chain step plays driven at
        its velocities."""
        cid = self.world.cid
        for art, qd in self.velocities():
            idx = list(range(len(art.records)))
            pb.setJointMotorControlArray(
                art.uid,
                idx,
                pb.VELOCITY_CONTROL,
                targetVelocities=[float(x) for x in qd],
                forces=[LIMIT_FORCE] * len(idx),
                physicsClientId=cid,
            )

    def _take(self, art, limited) -> None:
        rows = self.world.limit_rows
        for n in range(len(art.records)):
            rows.release(art, n)
        for n, (lo, hi) in limited:
            pb.changeDynamics(
                art.uid, n, jointLowerLimit=lo - OPEN, jointUpperLimit=hi + OPEN, physicsClientId=self.world.cid
            )

    def _give_back(self, art, limited, keep: set[int] | None = None) -> None:
        """The joints' own limits back, and their motors off but those of ``keep`` (driven by
        commands since)."""
        cid = self.world.cid
        for n, (lo, hi) in limited:
            pb.changeDynamics(art.uid, n, jointLowerLimit=lo, jointUpperLimit=hi, physicsClientId=cid)
        idx = [n for n in range(len(art.records)) if keep is None or n not in keep]
        if idx:
            pb.setJointMotorControlArray(
                art.uid, idx, pb.VELOCITY_CONTROL, forces=[0.0] * len(idx), physicsClientId=cid
            )
        super()._give_back(art, limited, keep)
