"""Drilling a voxel volume with a burr, as AMBF's volumetric drilling plugins do (`adfkit drill`,
docs/volumes.md): ``prepare`` (from a loaded scene to the volume, the burr, the tissues),
``inputs`` (tool path and labels files), ``task`` (the control step: contact, wear, removal),
``output`` (drilled slices, volume.yaml, surface, metrics, GIF)."""
