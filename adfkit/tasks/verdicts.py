"""The verdict on one hole pair and, when it fails, a reason a phantom modeller can act on.

A pair passes when, from the physics: neither the needle (tip, body or tail) nor the thread
pressed on the tissue with FORCED_N held, in any phase of the pair, and no tool with
TOOL_HIT_N (the earlier of the two is the verdict, before anything that followed it); the tip
went in through entry k and out through exit k inside each hole's real opening (the free square
inside its boundary capsules), tip first, overlapping each hole's ghost as it crossed (so the
ghost's friction acted there); the thread followed through both holes by the end of the pull;
the needle did not slip more than SLIP_LIMIT in the grasp while one arm held it; and the planner
reached every pose of the pair. The first rule broken is the verdict's ``rule`` and ``reason``.

The verdict reads only what the observer recorded (contacts of the needle, the thread and the
tools with the tissue bodies, with forces and points, and the needle's poses), never an engine.
The forces are in the newtons of the engine that took the record, and the limits they are held
to are the record's own (``force_limits``: those its observer held it to, per engine,
tasks/contact_forces.py); a record without them is read with the figures below.
"""

from __future__ import annotations

import math

from .holes import ghost_box

#: N: a tool pressing on the tissue at least this hard, held over 20 ms (a touch's
#: sustained_force_n: the mean of five control steps less the largest), fails the pair. Every
#: touch is recorded (metrics' tool_tissue_events, each pair's tool_tissue_max_n); a jaw brushing
#: a hole's boundary as it takes the needle beside it peaks at 15-60 N for a step in PyBullet's
#: stiff contacts and at up to 800 N in MuJoCo's rigid ones, a wrist driven into the tissue holds
#: thousands
TOOL_HIT_N: float | None = 50.0

#: N: the needle (its tip, body or tail) or the thread pressing on a tissue body at least this
#: hard, held over 20 ms as a tool's touch is (the mean of five control steps less the largest),
#: fails the pair in whichever phase: the driver forced it through what should have let it pass.
#: Good runs press with a few newtons (the needle lying on the tissue, picked up and carried
#: over it; brushing a hole's boundary), forced ones with hundreds (docs/suture.md has both)
FORCED_N = 40.0
#: N: the same for the thread. Drawn through the holes by the puller and dragged over them in
#: the hand-back, its tension presses it on their boundaries and the phantom's edges: up to 12 N
#: held in PyBullet, up to 322 N in MuJoCo's rigid contacts on good runs (docs/suture.md has the
#: figures; 300 N failed a good MuJoCo seed); a thread caught on the tissue holds more
THREAD_FORCED_N = 1000.0
#: m along the needle's arc from a hole within which a block is the hole's (blocked-at-entry,
#: blocked-at-exit); farther in, it is the channel's
AT_HOLE = 0.002
#: m off the planned arc beyond which a contact's place is given as a point, not along the arc
ON_ARC = 0.004
SLIP_LIMIT = 0.002  # m the needle may move in the grasp while one arm holds it
SLIP_SETTLE_S = 0.25  # s a grasp is given to settle after the other arm let go
BLOCK_N = 1.0  # N: a carried needle pressing on the tissue this hard on its way to a hole is blocked there
TOUCH_N = 0.05  # N: a contact at least this strong is a touch (recorded as an event, named in a reason)
STILL_TOUCHING_S = 0.1  # s: a touch that ended this near the episode's stop was still on when it stopped
RULES = (
    "not-tried",
    "blocked-at-entry",
    "blocked-in-channel",
    "blocked-at-exit",
    "pressed-on-tissue",
    "tool-hit-tissue",
    "reach",
    # blocked-at-entry again, without forcing: the tip stopped at the entry (_blocked_reason)
    "entry-missed",
    "entry-outside-opening",
    "entry-not-tip-first",
    "entry-ghost-off-hole",
    "left-boundary",
    "exit-missed",
    "exit-outside-opening",
    "exit-not-tip-first",
    "exit-ghost-off-hole",
    "thread-not-through",
    "slip",
)


def force_limits(scale: float = 1.0) -> dict[str, float | None]:
    """The force limits above, in N, each times ``scale`` (an engine's, contact_forces.limit_scale)."""
    written = {
        "tool_hit_n": TOOL_HIT_N,
        "forced_n": FORCED_N,
        "thread_forced_n": THREAD_FORCED_N,
        "block_n": BLOCK_N,
        "touch_n": TOUCH_N,
    }
    return {k: None if v is None else v * scale for k, v in written.items()}


def limits_of(obs) -> dict[str, float | None]:
    """The force limits ``obs`` was taken with (its ``force_limits``), else the figures above."""
    return getattr(obs, "force_limits", None) or force_limits()


def _mm(m: float) -> str:
    return f"{m * 1000:.1f} mm"


def in_pair(phase: str | None, k: int, first: bool) -> bool:
    """Whether a phase belongs to pair k (the pick-up belongs to the first pair)."""
    if not phase:
        return False
    return phase.endswith(f" {k}") or (first and phase in ("pick up", "settle"))


def phase_pair(phase: str | None, task) -> int | None:
    """The pair a phase belongs to: its number ("insert 2"), the first pair's for the pick-up
    and the settling, else None."""
    if not phase:
        return None
    last = phase.split()[-1]
    if last.isdigit():
        return int(last)
    pairs = getattr(task, "pairs", None)
    return pairs[0].index if pairs and phase in ("pick up", "settle") else None


def _label(hole) -> str:
    """A hole's name in a reason: its boundary body's (Entry1), else its ghost's."""
    return getattr(hole, "label", None) or hole.name


def _hole(obs, k: int, kind: str):
    return next(h for h in obs.holes if h.pair == k and h.kind == kind)


def _narrower_than_wire(obs, hole) -> str:
    """ "<hole>'s opening (w) is narrower than the needle's wire (d)" when it is, else ""."""
    width = 2 * float(min(hole.half)) if hole.half is not None else None
    if width is None or width >= 2 * obs.wire_radius:
        return ""
    return f"{_label(hole)}'s opening ({_mm(width)}) is narrower than the needle's wire ({_mm(2 * obs.wire_radius)})"


def _blocked_reason(obs, k: int, entry, phase: str = "", forces=None) -> tuple[str, str]:
    """What stopped the tip at entry k: the bodies the tip pressed on (else the needle) in
    ``phase`` (the insertion), with their contact forces (``forces`` where the caller chose
    them), and a boundary narrower than the wire."""
    phase = phase or f"insert {k}"
    label = _label(entry)
    narrow = _narrower_than_wire(obs, entry).replace(f"{label}'s opening", "; its opening", 1)
    at_tip = {} if forces is not None else getattr(obs, "tip_contacts", {}).get(phase, {})
    forces = forces if forces is not None else (at_tip or obs.needle_contacts.get(phase, {}))
    if forces:
        who = "the tip" if at_tip else "the needle"
        touch = limits_of(obs)["touch_n"]
        hits = ", ".join(f"{b} ({f:.1f} N)" for b, f in sorted(forces.items(), key=lambda kv: -kv[1]) if f >= touch)
        return "blocked-at-entry", (
            f"blocked at {label}: {who} pressed on {hits or 'the tissue'} and came no "
            f"nearer than {_mm(entry.closest)} to the opening{narrow}"
        )
    return "entry-missed", f"the tip never went through {label} (nearest {_mm(entry.closest)} from its opening){narrow}"


def _met_while_carried(obs, phase: str) -> dict[str, float]:
    """{tissue body: largest N} the carried needle (not the thread) came to press on, BLOCK_N or
    more, in ``phase``, still touching it when the episode stopped: not the bed it was lifted
    from (a touch that began before the carry), nor a bump it left behind. (A phantom's tray,
    pressed with 4.7 N as the needle left it, made a joint limit reached on the way
    "blocked at Entry1".)"""
    path = getattr(obs, "tip_path", None)
    stop = path[-1][0] if path else math.inf
    block = limits_of(obs)["block_n"]
    out: dict[str, float] = {}
    for e in getattr(obs, "needle_events", None) or []:
        if e.get("part") == "thread" or e["phase"] != phase or e["max_force_n"] < block:
            continue
        if stop - e["t_end"] > STILL_TOUCHING_S:
            continue
        out[e["tissue"]] = max(out.get(e["tissue"], 0.0), e["max_force_n"])
    return out


def _ghost_box(ghost) -> tuple[float, float, float] | None:
    """A hole ghost's box (holes.ghost_box), None where it has none or is not a scene's ghost."""
    try:
        return ghost_box(ghost)
    except AttributeError:
        return None


def _crossing_fault(c: dict, hole, side: str) -> tuple[str, str] | None:
    if c["outside_opening_m"] > 0:
        return f"{side}-outside-opening", (
            f"the tip crossed {_label(hole)}'s plane {_mm(c['outside_opening_m'])} "
            f"outside its opening (at {c['at_mm'][0]:.1f}, {c['at_mm'][1]:.1f} mm)"
        )
    if not c["tip_leading"]:
        return f"{side}-not-tip-first", f"the needle went through {_label(hole)} backwards (tail first)"
    if not c["ghost_overlap"]:
        g = hole.ghost.ghost
        box = _ghost_box(hole.ghost)
        half = getattr(hole, "half", None)
        if box is not None and half is not None and min(box[:2]) < 2 * float(min(half)) and hole.ghost_offset < 5e-4:
            return f"{side}-ghost-off-hole", (
                f"the tip went through {_label(hole)}'s opening {math.hypot(*c['at_mm']):.1f} mm from its centre "
                f"but not through its ghost {g.name or g.identifier}: the ghost ({box[0] * 1000:.1f} × "
                f"{box[1] * 1000:.1f} mm) covers less than the opening ({2 * half[0] * 1000:.1f} × "
                f"{2 * half[1] * 1000:.1f} mm), and no friction holds the needle beside it; make the ghost "
                "as large as the opening"
            )
        return f"{side}-ghost-off-hole", (
            f"the tip went through {_label(hole)}'s opening but not through its ghost "
            f"{g.name or g.identifier}, whose centre is {_mm(hole.ghost_offset)} off "
            "the hole: no friction holds the needle there; put the ghost on the hole"
        )
    return None


def _back_out(crossings: list[dict], t_in: float, t_exit: float) -> list[dict]:
    """The tip's crossings back out of the entry, between going in (t_in) and out of the exit
    (t_exit), that it did not undo: a tip that trembled back across the entry's plane for a
    control step and went on in through the opening has not left the boundary (MuJoCo, seed 5,
    pair 4: out for 4 ms, in again, out through the exit 2.9 s later); back in beside the
    opening, it has."""
    back: list[dict] = []
    for c in crossings:
        if not t_in < c["t"] < t_exit:
            continue
        if not c["inward"]:
            back.append(c)
        elif c["outside_opening_m"] <= 0.0:
            back = []  # in again through the opening: it went on from there
    return back


def _who(ev: dict, where: dict) -> str:
    """The part that pressed, in words: the needle's tip, body (n mm from its tip) or tail, or
    the thread (element n, from the needle)."""
    if ev["part"] == "thread":
        return f"the thread (element {where['element']})" if where.get("element") else "the thread"
    if ev["part"] == "body" and where.get("from_tip_m") is not None:
        return f"the needle's body ({_mm(where['from_tip_m'])} from its tip)"
    return f"the needle's {ev['part']}"


def _static_note(obs, k: int, said: str = "") -> str:
    """What the check of the needle's swept arc before the episode found at pair k, if anything,
    less a hole's opening narrower than the wire that the reason ``said`` already."""
    found = getattr(obs.task, "sweep", {}).get(k) or ""
    narrow = "narrower than the needle's wire"
    notes = [n for n in found.split("; ") if n and not (narrow in n and narrow in said and n.split("'s")[0] in said)]
    return f"; before the run: {'; '.join(notes)}" if notes else ""


def _pressing(ev: dict, on: str = "") -> str:
    """ "<part> pressed on <body> with up to N held over 20 ms (peak N)" for a forced touch."""
    w = ev["over_limit"]
    held = max(ev.get("sustained_force_n", 0.0), w["force_n"])
    return f"{_who(ev, w)} pressed on {on or ev['tissue']} with up to {held:.0f} N held over 20 ms (peak {ev['max_force_n']:.0f} N)"


def _forced(obs, k: int, first: bool, entry, exit_) -> tuple[float, str, str] | None:
    """The first touch of the needle or the thread in pair k's phases that held FORCED_N or more
    on the tissue: (when, rule, reason), the rule by where it was along the needle's arc; the
    reason names it, where and from when, then the pair's other touches over FORCED_N."""
    evs = [
        e
        for e in getattr(obs, "needle_events", [])
        if "over_limit" in e and in_pair(e["over_limit"]["phase"], k, first)
    ]
    if not evs:
        return None
    evs.sort(key=lambda e: e["over_limit"]["t"])
    ev = evs[0]
    w = ev["over_limit"]
    body, phase = ev["tissue"], w["phase"]
    past, before, off = w.get("past_entry_m"), w.get("before_exit_m"), w.get("off_arc_m")
    on_arc = past is not None and off is not None and off <= ON_ARC
    pushed = ""
    tip = w.get("tip") or {}
    driven = phase.split()[0] in ("insert", "regrasp", "pull")
    if driven and not on_arc and tip.get("off_arc_m") is not None and tip["off_arc_m"] <= ON_ARC:
        # pressed beside its arc while the tip was on it: the needle was pushed aside, where its tip was
        pushed = f" {_mm(off)} beside its arc" if off is not None else ""
        past, before, on_arc = tip["past_entry_m"], tip["before_exit_m"], True
    more = {}
    for e in evs[1:]:  # the other bodies and parts it was forced on, the strongest of each
        key = (e["tissue"], e["part"])
        if key != (body, ev["part"]) and (key not in more or e["sustained_force_n"] > more[key]["sustained_force_n"]):
            more[key] = e
    also = "".join(f"; {_pressing(e)}" for e in sorted(more.values(), key=lambda e: -e["sustained_force_n"])[:3])
    e_l, x_l = _label(entry), _label(exit_)
    in_through = [c["t"] for c in entry.crossings if c["inward"] and c["outside_opening_m"] <= 0.0]
    if not on_arc and phase == f"insert {k}" and not (in_through and in_through[0] <= w["t"]):
        # forced while driven into entry k before the tip went in through its opening, the needle
        # thrown beside its arc by what stopped it: the entry blocked it, wherever it was pushed
        at_tip = tip.get("past_entry_m")
        pushed = (
            f" (the tip {_mm(abs(at_tip))} {'before' if at_tip < 0 else 'past'} it, "
            f"{_mm(tip['off_arc_m'])} beside the needle's arc)"
            if at_tip is not None and tip.get("off_arc_m") is not None
            else ""
        )
        narrow = _narrower_than_wire(obs, entry)
        reason = f"blocked at {e_l}{pushed}: {_pressing(ev)} from t = {w['t']:.2f} s in {phase}{also}"
        return w["t"], "blocked-at-entry", reason + (f"; {narrow}" if narrow else "")
    then = f"{pushed} from t = {w['t']:.2f} s in {phase}"
    if on_arc and driven:
        for rule, hole, d, ahead in (
            ("blocked-at-entry", entry, past, "past"),
            ("blocked-at-exit", exit_, before, "before"),
        ):
            if d <= AT_HOLE:  # within AT_HOLE of the hole, or beyond it on the far side
                behind = "before" if ahead == "past" else "past"
                at = ("the tip " if pushed else "") + (f"{_mm(d)} {ahead} it" if d >= 0 else f"{_mm(-d)} {behind} it")
                narrow = _narrower_than_wire(obs, hole)
                reason = f"blocked at {_label(hole)} ({at}): {_pressing(ev)}{then}{also}"
                return w["t"], rule, reason + (f"; {narrow}" if narrow else "")
        return (
            w["t"],
            "blocked-in-channel",
            (
                f"the channel between {e_l} and {x_l} is blocked {_mm(past)} past {e_l} by {body}"
                + (" (where the tip was)" if pushed else "")
                + ": "
                f"{_pressing(ev, 'it')}{then}{also}"
            ),
        )
    if on_arc:
        where = f", {_mm(past)} past {e_l}" if past >= 0 else f", {_mm(-past)} before {e_l}"
        where += " on the needle's arc"
    else:
        where = " at ({}) mm".format(", ".join(f"{v * 1000:.1f}" for v in w["point_m"]))
    return w["t"], "pressed-on-tissue", f"{_pressing(ev)}{then}{where}{also}"


def _tool_hit(obs, k: int, first: bool) -> tuple[float, str, str] | None:
    """The first touch of a tool in pair k's phases that held TOOL_HIT_N or more on the tissue."""
    limit = limits_of(obs)["tool_hit_n"]
    if limit is None:
        return None
    hits = []
    for e in obs.tool_events:
        over = e.get("over_limit")
        pressed = e.get("sustained_force_n", e["max_force_n"])
        if over is None and pressed >= limit:  # recorded without the moment (older records)
            over = {"t": e["t_start"], "phase": e["phase"], "force_n": pressed}
        if over is not None and in_pair(over["phase"], k, first):
            hits.append((over["t"], e, over))
    if not hits:
        return None
    t, e, over = min(hits, key=lambda h: h[0])
    return (
        t,
        "tool-hit-tissue",
        (
            f"{e['arm']}'s {e['link']} hit {e['tissue']} with {e.get('sustained_force_n', over['force_n']):.1f} N "
            f"held over 20 ms (peak {e['max_force_n']:.1f} N) during {over['phase']} (t = {over['t']:.2f} s): "
            "the tool cannot reach the needle there without pressing on the tissue"
        ),
    )


def _judge(obs, pair, failure: str | None, failure_phase: str | None, first: bool, out: dict):
    k = pair.index
    entry, exit_ = _hole(obs, k, "entry"), _hole(obs, k, "exit")
    failed_here = failure is not None and in_pair(failure_phase, k, first)
    log = [name for name, _ in obs.task.phase_log]
    if log and not any(in_pair(name, k, first) for name in log):
        return "not-tried", f"not tried: the episode stopped before it ({failure or 'no failure recorded'})"
    ins = [c for c in entry.crossings if c["inward"]]
    outs_all = [c for c in exit_.crossings if not c["inward"]]
    # forcing and a tool pressing on the tissue are judged first, whatever came after them (a
    # planner that then lost the needle, a thread that did not follow): the earlier of the two
    physical = [f for f in (_forced(obs, k, first, entry, exit_), _tool_hit(obs, k, first)) if f is not None]
    if physical:
        _, rule, reason = min(physical, key=lambda f: f[0])
        for key, crossings in (("entry_passed_s", ins), ("exit_passed_s", outs_all)):
            through = [c for c in crossings if c["outside_opening_m"] <= 0.0]
            out[key] = through[0]["t"] if through else None
        if rule != "tool-hit-tissue":
            reason += _static_note(obs, k, reason)
        return rule, reason + (f"; then the planner stopped: {failure}" if failed_here else "")
    if not ins:
        approach = f"carry {k}"
        met = _met_while_carried(obs, approach) if failed_here and failure_phase == approach else {}
        if met:
            # stopped on the way to the hole with the needle pressing on the tissue: what is there blocks it
            rule, reason = _blocked_reason(obs, k, entry, approach, met)
            return rule, f"{reason}, before the insertion (the planner stopped: {failure})"
        if failed_here and not (failure_phase or "").startswith(("insert", "regrasp")):
            return "reach", failure
        rule, reason = _blocked_reason(obs, k, entry)
        return rule, reason + _static_note(obs, k, reason)
    c_in = ins[0]
    if c_in["outside_opening_m"] > 0 and obs.needle_contacts.get(f"insert {k}"):
        # deflected by the tissue: the tip crossed the hole's plane beside the opening, not through it
        rule, reason = _blocked_reason(obs, k, entry)
        return rule, (
            f"{reason}; the tip was pushed across {_label(entry)}'s plane "
            f"{_mm(c_in['outside_opening_m'])} outside the opening"
        )
    out["entry_passed_s"] = c_in["t"]
    fault = _crossing_fault(c_in, entry, "entry")
    if fault:
        return fault
    outs = [c for c in outs_all if c["t"] > c_in["t"]]
    back = _back_out(entry.crossings, c_in["t"], outs[0]["t"] if outs else math.inf)
    touch = limits_of(obs)["touch_n"]
    at_tip = {b: f for b, f in getattr(obs, "tip_contacts", {}).get(f"insert {k}", {}).items() if f >= touch}
    if back and at_tip:
        # in through the opening and pushed back out by what the tip ran into: the channel is closed
        hits = ", ".join(f"{b} ({f:.1f} N)" for b, f in sorted(at_tip.items(), key=lambda kv: -kv[1]))
        return "blocked-at-entry", (
            f"blocked past {_label(entry)}: the tip went in through its opening at t = {c_in['t']:.2f} s, "
            f"pressed on {hits} and came back out at t = {back[0]['t']:.2f} s before reaching {_label(exit_)}"
            + _static_note(obs, k)
        )
    if back:
        return "left-boundary", (
            f"the needle left the boundary of {_label(entry)}: the tip came back out at "
            f"t = {back[0]['t']:.2f} s before reaching {_label(exit_)}"
        )
    if not outs:
        if failed_here:
            return "reach", failure
        return "exit-missed", (
            f"exit missed by {_mm(exit_.closest)}: the tip never came out through {_label(exit_)}"
            + _static_note(obs, k)
        )
    out["exit_passed_s"] = outs[0]["t"]
    fault = _crossing_fault(outs[0], exit_, "exit")
    if fault:
        return fault
    th = obs.thread_by_pair.get(k)
    if th is None and f"pull {k}" not in log and not failed_here:
        pass  # a task that does not pull the thread (a Gymnasium pair): the tip's pass is the test
    elif th is None:
        if failed_here:
            return "reach", failure
        return "thread-not-through", "the pull of the thread never finished"
    if th is not None:
        out["thread_through_m"] = th["length_m"]
    if th is not None and not (th["through_entry"] and th["through_exit"]):
        miss = " and ".join(
            n for n, ok in ((_label(entry), th["through_entry"]), (_label(exit_), th["through_exit"])) if not ok
        )
        return "thread-not-through", f"the thread did not follow the needle through {miss}"
    for s in obs.slips:
        if in_pair(s["phase"], k, first):
            return "slip", (
                f"the needle slipped {_mm(s['slip_m'])} in {s['arm']}'s grasp during {s['phase']} "
                f"(limit {_mm(obs_slip_limit())} while one arm holds)"
            )
    if failed_here:
        return "reach", failure
    return None


def obs_slip_limit() -> float:
    return SLIP_LIMIT


def pair_verdict(obs, pair, failure: str | None = None, failure_phase: str | None = None) -> dict:
    """The verdict on ``pair`` from what the observer recorded (see the module docstring)."""
    first = obs.task.pairs[0] is pair
    out = {
        "pair": pair.index,
        "entry": pair.entry_name,
        "exit": pair.exit_name,
        "entry_passed_s": None,
        "exit_passed_s": None,
        "thread_through_m": None,
    }
    fault = _judge(obs, pair, failure, failure_phase, first, out)
    out["tool_tissue_max_n"] = max(
        (e["max_force_n"] for e in obs.tool_events if in_pair(e["phase"], pair.index, first)), default=0.0
    )
    out["passed"] = fault is None
    out["verdict"] = "passed" if fault is None else "failed"
    out["rule"], out["reason"] = (None, None) if fault is None else fault
    return out
