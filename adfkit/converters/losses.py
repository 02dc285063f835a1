"""What a conversion could not carry over: one record per element and feature, never silent."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, order=True)
class Loss:
    """``element`` is the object as the source names it (an ADF identifier, a URDF link or
    joint name, an MJCF element), ``feature`` what was dropped or changed, ``reason`` why."""

    element: str
    feature: str
    reason: str

    def __str__(self) -> str:
        return f"{self.element}: {self.feature}: {self.reason}"


def loss_keys(losses) -> list[tuple[str, str]]:
    """(element, feature) pairs, sorted: what tests compare."""
    return sorted((l.element, l.feature) for l in losses)


def axis_tilt(joint, parent, child) -> Loss | None:
    """The loss of a joint read into ADF whose axes AMBF's shortest arcs snap (identity below
    1e-3 rad, taken in the bodies' inertial frames: semantics.snapped_axis_tilt); None if none."""
    from ..model.semantics import snapped_axis_tilt

    tilt = snapped_axis_tilt(joint, parent, child)
    if not tilt:
        return None
    return Loss(
        joint.identifier,
        "axis tilt",
        f"an axis differs by {tilt:.3g} rad from one AMBF snaps it to "
        "(shortest arcs below 1e-3 rad are the identity): ADF rounds it away",
    )
