"""`adfkit convert IN OUT`: ADF ⇄ URDF ⇄ MJCF through the scene model; prints what was dropped."""

from __future__ import annotations

import sys

from .. import jsonout

NAME = "convert"
HELP = "convert a model between ADF, URDF and MJCF, listing everything the target cannot express"


def add_arguments(p) -> None:
    p.add_argument("input", help="model file: .yaml (ADF), .urdf, .xml (MJCF)")
    p.add_argument("output", help="file to write; its extension picks the format unless --to is given")
    p.add_argument("--from", dest="source_format", choices=("adf", "urdf", "mjcf"), help="input format")
    p.add_argument("--to", choices=("adf", "urdf", "mjcf"), help="output format")
    p.add_argument("--fail-on-loss", action="store_true", help="exit 1 when anything was dropped or changed")
    p.add_argument("--json", action="store_true", help="print the losses as JSON")


def run(args) -> int:
    from pathlib import Path

    from .. import inputs
    from ..converters import format_of, read, write
    from ..diagnostics import AdfError, SourceLocation, error

    src, dst = Path(args.input), Path(args.output)
    inputs.check_file(src, "xml", what="model file")  # a regular file (adfkit.inputs); readers check again
    inputs.check_path_text(dst)
    if src.resolve() == dst.resolve():
        raise AdfError(
            error(
                "convert-overwrite",
                "input and output are the same file",
                SourceLocation(str(dst)),
                "write the converted model to a new file",
            )
        )
    fin, fout = format_of(src, args.source_format), format_of(dst, args.to)
    model, read_losses = read(src, fin)
    write_losses = write(model, dst, fout)
    losses = [("read", l) for l in read_losses] + [("write", l) for l in write_losses]
    if args.json:
        jsonout.dump(
            {
                "input": str(src),
                "output": str(dst),
                "from": fin,
                "to": fout,
                "losses": [
                    {"stage": s, "element": l.element, "feature": l.feature, "reason": l.reason} for s, l in losses
                ],
            },
            sys.stdout,
            indent=2,
        )
        sys.stdout.write("\n")
    else:
        vols = sum(1 for v in model.volumes if v.defined)
        print(
            f"{src} ({fin}) -> {dst} ({fout}): {len(model.bodies)} bodies, {len(model.joints)} joints"
            + (f", {vols} volume(s) as their iso-surfaces" if vols else "")
        )
        if losses:
            print(f"{len(losses)} item(s) not carried over:")
            for stage, l in losses:
                print(f"  {stage}: {l}")
        else:
            print("nothing lost")
    return 1 if (losses and args.fail_on_loss) else 0
