"""`adfkit validate PATH...`: check ADF files, folders (recursively) or a launch file and
everything it names, for people (text) and for CI (json, github annotations, sarif)."""

from __future__ import annotations

import sys

NAME = "validate"
HELP = "validate ADF files, folders or a launch file (schema + semantic rules)"
DESCRIPTION = HELP + ". Exit status: 0 clean, 1 findings at or above --fail-on, 2 usage error or unreadable input."
UNREADABLE = ("file-not-found", "file-unreadable", "bad-path", "not-a-regular-file", "file-too-large")
KIND_CHOICES = ["launch", "world", "input_devices", "model", "colors"]


def add_arguments(p) -> None:
    p.add_argument("paths", nargs="+", metavar="PATH", help="ADF files, folders, or launch files")
    p.add_argument("--kind", choices=KIND_CHOICES, help="file kind (detected from the keys by default)")
    p.add_argument(
        "--format",
        "-f",
        choices=["text", "json", "github", "sarif"],
        default="text",
        help="output format (default text)",
    )
    p.add_argument(
        "--fail-on",
        choices=["error", "warning", "info", "never"],
        default="error",
        help="exit 1 when a finding has at least this severity (default error)",
    )
    p.add_argument(
        "--select",
        action="append",
        default=[],
        metavar="RULE",
        help="report only these rules (repeatable, comma-separated)",
    )
    p.add_argument(
        "--ignore",
        action="append",
        default=[],
        metavar="RULE",
        help="do not report these rules (repeatable, comma-separated)",
    )
    p.add_argument(
        "--jobs",
        "-j",
        type=int,
        default=0,
        metavar="N",
        help="check on N local processes (default 0: one per CPU for trees of 48 files and more, "
        "else this process alone; 1: this process)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="check on W Ray workers (big trees; same output, same order); default 1: in this process",
    )
    p.add_argument("--address", help="with --workers: a Ray cluster address (default: a local Ray)")
    p.add_argument("--no-follow", action="store_true", help="do not follow launch/world files to the files they name")
    p.add_argument(
        "--skip-non-adf",
        action="store_true",
        help="silently skip YAML files that are not ADF (unknown kind), e.g. in a pre-commit hook",
    )
    p.add_argument(
        "--min-severity",
        choices=["error", "warning", "info"],
        default="info",
        help="hide findings below this severity (default: show all)",
    )


def _rules(values: list[str]) -> set[str]:
    return {r.strip() for v in values for r in v.split(",") if r.strip()}


def run(args) -> int:
    from ..diagnostics import Severity
    from ..validator import RULES, reporters

    select, ignore = _rules(args.select), _rules(args.ignore)
    unknown = sorted((select | ignore) - set(RULES))
    if unknown:
        print(
            f"adfkit validate: unknown rule(s): {', '.join(unknown)} (docs/validate.md lists the rules)",
            file=sys.stderr,
        )
        return 2
    if args.workers > 1 or args.address:
        from ..fanout import validate_parallel

        results, problems = validate_parallel(args.paths, args.kind, not args.no_follow, args.workers, args.address)
    else:
        from ..validator.engine import expand, validate_files_jobs

        files, problems = expand(args.paths)
        results = validate_files_jobs(files, args.kind, not args.no_follow, args.jobs)
    shown_min = Severity.parse(args.min_severity)
    diags = list(problems)
    texts = {}
    checked = 0
    for res in results:
        if args.skip_non_adf and res.kind is None and [d.rule for d in res.diagnostics] == ["unknown-kind"]:
            continue
        checked += 1
        texts[str(res.path)] = res.text
        diags += res.diagnostics
    diags = [d for d in diags if (not select or d.rule in select) and d.rule not in ignore and d.severity >= shown_min]
    out = sys.stdout
    if args.format == "text":
        reporters.write_text(diags, out, texts, files=checked)
    elif args.format == "json":
        reporters.write_json(diags, out, files=checked)
    elif args.format == "github":
        reporters.write_github(diags, out)
    else:
        reporters.write_sarif(diags, out)
    # A file named on the command line that cannot be read at all: usage error. (A file that
    # another one names is located at the naming key, a finding in that file.)
    if problems or any(d.rule in UNREADABLE and (d.location is None or not d.location.line) for d in diags):
        return 2
    if args.fail_on == "never":
        return 0
    threshold = Severity.parse(args.fail_on)
    return 1 if any(d.severity >= threshold for d in diags) else 0
