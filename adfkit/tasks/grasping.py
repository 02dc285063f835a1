"""Where a PSM takes the needle: grasp candidates around and along the wire, each scored by how
far it keeps the tool from the tissue along the plan (adfkit/tasks/clearance.py), then by the
closed-form IK's joint margin. A mixin of SutureTask (it reads the task's needle geometry,
arms, tissue and tool shapes)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..runner.psm import PSM
from ..runner.psm_kinematics import PRISMATIC
from ..runner.rotations import invert
from .clearance import clearances

JAW_DEPTH = 0.01  # m from the end effector to the point between the jaws (LND: along z_E)
#: m from the end effector to where the wire is held: 1 mm short of the fingers' ends (11.5 mm), so
#: that the jaws reach no farther than the wire's far side (a needle lying on the tissue is taken
#: from above without the fingers pressing into the tissue)
GRASP_DEPTH = 0.0105
BACK_OFF = 0.012  # m along -z_E before a grasp and after a release
TOOL_CLEARANCE = 0.0015  # m the planner keeps the tool's shapes from the tissue's where it can
#: m of clearance, read from the tissue's distance field, that leaves the tool off the tissue for
#: sure: more than the field's largest overstatement (its trilinear reading between nodes 1.5 mm
#: apart overstated a hole capsule's distance by up to 0.6 mm, measured at Exit1)
SURE_CLEARANCE = 0.0007
#: rad between the jaws as they come onto the wire: a 3.9 mm gap at the wire for its 1.2 mm, and
#: fingers 2.5 mm to each side instead of the 5.6 mm of a fully opened jaw, beside the tissue
JAW_APPROACH = 0.35
#: the tool's roll among q1..q6: its range (+-3.054 rad) is nearly a full turn, and the IK gives it
#: in (-pi, pi], so a Cartesian path that turns it past +-pi shows as a jump of nearly 2 pi
ROLL = 3
GRASP_STEP = math.radians(6)  # the planner tries grasps this far apart along the wire ...
MIN_GRASP = math.radians(8)  # ... from this far from the tip or the tail (the jaws' width)


class SutureError(RuntimeError):
    """The planner cannot go on (no reachable grasp, a lost needle, ...)."""


@dataclass
class Grasp:
    """Where a PSM holds the needle: the end effector's pose in the needle frame."""

    ee_in_needle: np.ndarray
    margin: float
    clearance: float = math.inf  # m the tool keeps from the tissue where the plan checked it
    #: which of the needle poses the clearance was checked at gives it (the first's approach
    #: along the jaw axis counts as the first), and the end effector's world pose there
    nearest_at: int = -1
    nearest_ee: np.ndarray | None = None


class GraspChoice:
    def grasp_candidates(self, phi: float):
        """End-effector poses in the needle frame that hold the wire at arc angle phi between
        the jaws (the wire across the opening direction y_E): around the wire in 15° steps,
        both ways, the wire square to the jaws or turned up to 45° about y_E. Each comes with
        its turn (rad), which the choice penalises slightly."""
        g = self.geom
        a = g.arc_in_needle
        p = g.point(phi)
        t = a[:3, :3] @ np.array([-math.sin(phi), math.cos(phi), 0.0])
        radial = a[:3, :3] @ np.array([math.cos(phi), math.sin(phi), 0.0])
        n = a[:3, 2]
        out = []
        for turn in np.radians([0.0, 25.0, -25.0, 45.0, -45.0]):
            for sign in (1.0, -1.0):
                for beta in np.radians(np.arange(0, 360, 15)):
                    z0 = math.cos(beta) * -radial + math.sin(beta) * n
                    x0 = sign * t
                    x = math.cos(turn) * x0 - math.sin(turn) * z0
                    z = math.sin(turn) * x0 + math.cos(turn) * z0
                    m = np.eye(4)
                    m[:3, :3] = np.c_[x, np.cross(z, x), z]
                    m[:3, 3] = p - GRASP_DEPTH * z
                    out.append((m, abs(float(turn))))
        return out

    def _along_wire(self, phi: float, clear_at: tuple):
        """Candidates at phi and, where the tool's clearance is checked, at other places of the
        same end of the wire (from MIN_GRASP up to phi), nearest to phi first."""
        yield from self.grasp_candidates(phi)
        if not clear_at:
            return
        tail_end = phi < -self.geom.span / 2
        end = -self.geom.span if tail_end else 0.0
        room = abs(phi - end) - MIN_GRASP
        for d in np.arange(GRASP_STEP, room + 1e-9, GRASP_STEP):
            yield from self.grasp_candidates(phi - d if tail_end else phi + d)

    def _margin(self, psm: PSM, ee_world: np.ndarray) -> float:
        return self._reach(psm, ee_world)[0]

    def _reach(self, psm: PSM, ee_world: np.ndarray) -> tuple[float, float]:
        """(the joint margin at an end-effector pose, the tool's roll there); (-1, nan) where the
        IK finds no solution within the limits."""
        try:
            q = psm.kin.ik(invert(psm.base_in_world()) @ ee_world)
        except ValueError:
            return -1.0, math.nan
        lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
        return float(np.min(np.minimum(q - lo, hi - q) / (hi - lo))), float(q[ROLL])

    def choose_grasp(
        self,
        psm: PSM,
        phi: float,
        needle_poses: list,
        down_at: np.ndarray | None = None,
        what: str = "",
        clear_at: tuple = (),
        joint_moves: tuple = (),
    ) -> Grasp:
        """The candidate grasp reachable at every needle pose that keeps the tool farthest from
        the tissue (up to TOOL_CLEARANCE) at the needle poses ``clear_at`` (the first one also
        on the approach along the jaw axis), then with the widest joint margin (with
        ``down_at``: the jaws must point down at that needle pose, to come from above).

        The needle goes from one of ``needle_poses`` to the next along a Cartesian path, except
        into the indices ``joint_moves`` (a move in joint space). On a Cartesian path the tool's
        roll must not pass +-pi: that lies outside its limits, and the servo would hold it at one
        limit while the needle turned on (a grasp of the corpus set's pair 1 asked for it at the
        end of the insertion, and the roll, clipped, came back at the other limit a full turn
        away and threw the needle out of the tissue)."""
        cands = [
            (m, turn) for m, turn in self._along_wire(phi, clear_at) if down_at is None or (down_at @ m)[2, 2] <= -0.5
        ]
        if not cands:
            raise SutureError(f"{psm.name}: no grasp of the needle from above ({what})")
        ee_in_n = np.array([m for m, _ in cands])
        clear = np.full(len(cands), TOOL_CLEARANCE)
        nearest = np.zeros(len(cands), dtype=int)  # where each candidate's clearance is least
        nearest_ee = np.zeros((len(cands), 4, 4))

        def fold(now: np.ndarray, i: int, ee: np.ndarray) -> np.ndarray:
            less = now < clear
            nearest[less], nearest_ee[less] = i, ee[less]
            return np.minimum(clear, now)

        for i, pose in enumerate(clear_at):
            # the jaws as they come onto the wire there: wide open onto a needle lying on the tissue
            tool = self.tools_wide[psm.name] if i == 0 and down_at is not None else self.tools[psm.name]
            ee = pose[None] @ ee_in_n
            clear = fold(clearances(self.tissue_shapes, tool, ee, TOOL_CLEARANCE), i, ee)
            if i == 0:  # and on the way in, along the jaw axis
                for f in (1.0, 2 / 3, 1 / 3):
                    back = ee.copy()
                    back[:, :3, 3] -= f * BACK_OFF * ee[:, :3, 2]
                    clear = fold(clearances(self.tissue_shapes, tool, back, TOOL_CLEARANCE), i, back)
        # the choice: the clearance (up to TOOL_CLEARANCE, in tenths of a millimetre), then the
        # wider joint margin
        clear_q = np.round(clear / 1e-4)
        best, best_key = None, None
        for i in np.argsort(-clear_q, kind="stable"):
            if best_key is not None and clear_q[i] < best_key[0]:
                break  # the rest come nearer the tissue
            m, turn = cands[i]
            first = needle_poses[0] @ m
            back = first.copy()
            back[:3, 3] -= BACK_OFF * first[:3, 2]
            worst = self._margin(psm, back)  # the jaws come onto the wire along their axis
            roll = math.nan
            for k, pose in enumerate(needle_poses):
                if worst <= 0:
                    break
                margin, was = self._reach(psm, pose @ m)
                worst = min(worst, margin)
                if k > 0 and k not in joint_moves and abs(was - roll) > math.pi:
                    worst = -1.0  # the roll would pass +-pi on the way from the previous pose
                roll = was
            margin = worst - 0.02 * turn
            key = (float(clear_q[i]), margin)
            if worst > 0 and (best_key is None or key > best_key):
                best, best_key = Grasp(m, margin, float(clear[i]), int(nearest[i]), nearest_ee[i].copy()), key
        if best is None:
            raise SutureError(
                f"{psm.name}: no grasp of the needle reachable along the whole plan ({what})"
                + self._shortfall(psm, [m for m, _ in cands], needle_poses)
            )
        return best

    def _shortfall(self, psm: PSM, ee_in_needle: list, needle_poses: list) -> str:
        """How far the nearest of the grasps misses: "; the nearest needs <arm>'s <joint> n mm
        (or degrees) past its limit with the needle's tip n mm from <hole>", or "" where the IK
        finds no configuration at all."""
        base_inv = invert(psm.base_in_world())
        lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
        best = None
        for m in ee_in_needle[:: max(1, len(ee_in_needle) // 240)]:
            worst = None
            for pose in needle_poses:
                try:
                    q = psm.kin.ik(base_inv @ pose @ m, check_limits=False)
                except ValueError:
                    worst = None
                    break
                over = np.maximum(lo - q, 0.0) + np.maximum(q - hi, 0.0)
                i = int(np.argmax(over / (hi - lo)))
                if over[i] > 0 and (worst is None or over[i] / (hi[i] - lo[i]) > worst[0]):
                    worst = (over[i] / (hi[i] - lo[i]), i, float(over[i]), pose)
            if worst is not None and (best is None or worst[0] < best[0]):
                best = worst
        if best is None:
            return ""
        _, i, over, pose = best
        name = psm.kin.joint_names[i]
        amount = f"{over * 1000:.1f} mm" if psm.kin.links[i].joint_type == PRISMATIC else f"{math.degrees(over):.1f}°"
        return f"; the nearest needs {psm.name}'s {name} {amount} past its limit{self._tip_near(pose)}"

    def _tip_near(self, needle_pose: np.ndarray) -> str:
        """ " with the needle's tip n mm from <hole>" for the hole of the task's pairs nearest the tip."""
        from .holes import hole_frame, hole_label

        tip = (needle_pose @ np.r_[self.geom.tip, 1.0])[:3]
        holes = [(g, hole_frame(self.world, g)[:3, 3]) for p in getattr(self, "pairs", []) for g in (p.entry, p.exit)]
        if not holes:
            return ""
        g, at = min(holes, key=lambda h: float(np.linalg.norm(h[1] - tip)))
        return f" with the needle's tip {np.linalg.norm(at - tip) * 1000:.1f} mm from {hole_label(g)}"
