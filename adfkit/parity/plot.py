"""Each body's position gap over time, one panel per comparison (matplotlib, headless)."""

from __future__ import annotations

from pathlib import Path


def plot_gaps(comparisons, path: Path, title: str, top: int = 8) -> None:
    """The ``top`` bodies with the largest gaps drawn over time, the tolerance dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(comparisons), 1, figsize=(6, 2.5 * len(comparisons)), squeeze=False)
    for ax, c in zip(axes[:, 0], comparisons):
        for g in c.bodies[:top]:
            ax.plot(c.times, g.position * 1e3, label=g.name.rsplit("/", 1)[-1])
        ax.axhline(c.tolerance_m * 1e3, color="k", ls="--", lw=0.8)
        ax.set_yscale("symlog", linthresh=0.01)
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel("simulated time (s)")
        ax.set_ylabel("position gap to AMBF (mm)")
        ax.set_title(f"{title}: AMBF vs adfkit {c.adfkit.side}", fontsize=9)
        ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    tmp = path.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=60)
    plt.close(fig)
    tmp.replace(path)
