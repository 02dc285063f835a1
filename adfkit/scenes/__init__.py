"""Builders that author the sample scenes from parameters (the project's own scenes).

Imported lazily: ``BUILDERS`` maps a scene name to a writer that imports its builder only
when called, so ``adfkit --help`` (which lists the names) loads none of them."""

from __future__ import annotations

from importlib import import_module


def _lazy(module: str, function: str):
    def write(out_dir):
        return getattr(import_module(f"{__name__}.{module}"), function)(out_dir)

    write.__name__ = function
    write.__doc__ = f"{function} from adfkit.scenes.{module} (imported on first use)"
    return write


BUILDERS = {
    "suturing": _lazy("suturing", "write_suturing"),
    "suturing-pad": _lazy("suturing_pad", "write_suturing_pad"),
    "soft-phantom": _lazy("soft_phantom", "write_soft_phantom"),
    "drilling": _lazy("drilling", "write_drilling"),
    "skull": _lazy("skull", "write_skull"),
    "parity": _lazy("parity", "write_parity"),
}

_EXPORTS = {
    "SuturingPadParams": "suturing_pad",
    "build_suturing_pad": "suturing_pad",
    "write_suturing_pad": "suturing_pad",
    "write_suturing": "suturing",
    "write_soft_phantom": "soft_phantom",
    "write_drilling": "drilling",
    "write_skull": "skull",
    "write_parity": "parity",
}


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["BUILDERS", *_EXPORTS]
