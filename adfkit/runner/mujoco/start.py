"""Where a six-dof-family joint's child starts: where the file puts it.

The MJCF writer places a child at its joint's zero, and the runner gives a six-dof-family joint
(six dof, six dof spring, cone twist, linear and torsion springs) one slide or hinge per free
axis of its joint frame (build.py: slides along x, y, z, then hinges about x, y, z, each turning
the axes after it: R = Rx·Ry·Rz, Bullet's RO_XYZ). AMBF's btRigidBodies start where the files'
`location`s put them, the joint's constraint acting from there: a pendulum on a cone-twist
joint, tilted in the file, swings from its tilt. So each such joint starts at the values that
put its child's joint frame where the file has it in its parent's (frame B in frame A: its
offset along A's axes, its XYZ angles); an axis the joint locks keeps 0 (AMBF's rows pull the
child onto it). Values within ZERO of 0 stay 0 (a thread laid straight starts exactly straight).
Where AMBF's bodies are asked for (``Options.bodies`` "ambf": ``adfkit run``, ``adfkit parity``);
the tasks were built and accepted with every such joint starting at its zero (the bundled suture's
thread starts straight, where its file bends its first elements 0.27 rad).
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.pose import Pose
from ...model.semantics import body_joint_frames
from ..plan import SPRING_KINDS
from ..rotations import euler_xyz, pose_to_matrix

#: m or rad: a start value this near the joint's zero is its zero
ZERO = 1e-9


def six_dof_start(model, data, joints) -> bool:
    """Set ``data.qpos`` of the six-dof-family joints in ``joints`` (the plan's: ADF joint, kind,
    parent BodyPlan, child BodyPlan, MuJoCo joint names) to the file's placements; whether any
    moved (then the caller runs mj_forward)."""
    moved = False
    for joint, kind, parent, child, names in joints:
        if kind not in SPRING_KINDS:
            continue  # a one-DOF joint: the writer's `ref` already starts it where the file does
        a, b = body_joint_frames(joint, parent.body, child.body)
        in_a = np.linalg.inv(pose_to_matrix(parent.body.location or Pose()) @ pose_to_matrix(a))
        rel = in_a @ pose_to_matrix(child.body.location or Pose()) @ pose_to_matrix(b)
        values = {"slide": rel[:3, 3], "hinge": euler_xyz(rel[:3, :3])}
        for name in names:
            suffix = name.rpartition("#")[2]  # build.py's "slidex" ... "hingez"
            v = float(values[suffix[:-1]]["xyz".index(suffix[-1])])
            if abs(v) <= ZERO:
                continue
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
            if jid < 0:
                continue
            data.qpos[model.jnt_qposadr[jid]] = v
            moved = True
    return moved
