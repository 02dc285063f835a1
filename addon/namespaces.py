"""Namespaces in object names, as AMBF's own add-on kept them: a Blender object named
``/ambf/env/psm/baselink`` is the ADF object ``baselink`` in namespace ``/ambf/env/psm/``.
*Strip namespaces* moves that prefix out of the names and into the model's ``namespace``."""

from __future__ import annotations

from adfkit.diagnostics import Diagnostic, SourceLocation, warning


def split_name(name: str) -> tuple[str, str]:
    """(namespace with its trailing '/', bare name); ('', name) when the name has none. A name
    ending in '/' has no bare part and is left whole."""
    i = name.rfind("/")
    if i < 0 or i == len(name) - 1:
        return "", name
    return name[: i + 1], name[i + 1 :]


def _ident(ident: str, prefix: str) -> str:
    """'BODY /ambf/env/base' -> 'BODY base' (the identifier's kind word stays)."""
    kind, _, rest = ident.partition(" ")
    return f"{kind} {rest[len(prefix) :]}" if rest.startswith(prefix) else ident


def strip_namespaces(scene, objects=None) -> list[str]:
    """Rename every ADF object whose name carries a namespace to its bare name (and its
    imported identifier with it). When the scene writes no namespace yet and all the stripped
    ones agree, that one becomes the model's ``namespace``; otherwise each dropped namespace is
    named in the lines returned (one per change), so nothing goes silently."""
    objs = [o for o in (objects if objects is not None else scene.objects) if o.adf.kind != "NONE"]
    said, seen = [], []
    for o in sorted(objs, key=lambda o: o.name):
        prefix, bare = split_name(o.name)
        if not prefix:
            continue
        old = o.name
        o.name = bare  # Blender appends .001 when the bare name is taken: said below
        if o.adf.identifier:
            o.adf.identifier = _ident(o.adf.identifier, prefix)
        seen.append(prefix)
        said.append(f"renamed '{old}' to '{o.name}'" + ("" if o.name == bare else f" ('{bare}' was taken)"))
    kinds = sorted(set(seen))
    sp = scene.adf
    if len(kinds) == 1 and not sp.use_namespace:
        sp.namespace, sp.use_namespace = kinds[0], True
        said.append(f"model namespace set to '{kinds[0]}'")
    elif kinds and [k for k in kinds if not (sp.use_namespace and k == sp.namespace)]:
        now = f"'{sp.namespace}'" if sp.use_namespace else "none"
        said.append(
            "namespaces removed from names: " + ", ".join(f"'{k}'" for k in kinds) + f"; the model's namespace is {now}"
        )
    return said


def findings(objects) -> list[Diagnostic]:
    """A warning for each ADF object whose name still carries a namespace: AMBF puts the model's
    namespace in front of every name, so '/ambf/env/base' would become '/ambf/env//ambf/env/base'."""
    out = []
    for o in objects:
        prefix, bare = split_name(o.name)
        if prefix and o.adf.kind not in ("NONE", "COLLISION_SHAPE", "COLLISION_MESH"):
            out.append(
                warning(
                    "namespace-in-name",
                    f"'{o.name}': the name carries the namespace '{prefix}'; AMBF puts the model's namespace "
                    f"in front of it",
                    SourceLocation(f"blender:{o.name}"),
                    f"use Strip namespaces (ADF scene panel): the object becomes '{bare}' in namespace '{prefix}'",
                )
            )
    return out
