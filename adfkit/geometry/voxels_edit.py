"""Editing a voxel volume with a spherical burr, and keeping its iso-surface up to date by
re-meshing only the blocks that changed.

Everything here works on the volume's own frame (metres, centred on the box, x along the
slice columns, y along the rows, z across the slices, as :mod:`adfkit.geometry.volume` lays
it out) and touches only the sub-block of voxels around the burr, so one step costs the same
on a 48³ and on a 256³ volume.

- :class:`EditableVolume`: the voxel values (as the slices hold them: uint8 for 8-bit
  slices, so the 512³ skull drills in a quarter of the memory of float32; or 0..1 floats), a
  label per voxel (fixed from the values read, so a removed voxel still counts for the tissue
  it was), and the wear each voxel has taken from the burr (a count of burr steps, uint8).
- :meth:`EditableVolume.burr_step`: one control step of the burr at a point: the contact force
  from the solid voxels (value at or above the iso-surface value) inside it, wear on every
  tissue voxel inside it, the voxels whose wear reached 1 removed (set to 0), counted per label.
- :class:`BlockSurface`: the iso-surface as marching-cubes meshes of fixed blocks
  (scikit-image); a removed voxel marks the (at most eight) blocks whose cells it is a corner
  of, and :meth:`BlockSurface.update` re-meshes those only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

BLOCK = 16  # cells per block side of the surface: a 16³ block meshes in ~0.15 ms


@dataclass
class Contact:
    """What one burr step found and did."""

    force: np.ndarray  # (3,) N in the volume frame, pushing the burr out of the solid voxels
    depth: float  # m, the deepest solid voxel centre inside the burr (0: no contact)
    touched: np.ndarray  # (labels,) protected tissue voxels inside the burr, per label id
    removed: np.ndarray  # (labels,) voxels removed this step, per label id


@dataclass
class EditableVolume:
    values: np.ndarray  # (count, rows, cols): the slices' values (uint8, uint16) or 0..1 floats, edited in place
    dimensions: np.ndarray  # (3,) metres along x, y, z
    iso: float  # values at or above it are solid (the iso-surface encloses them), in the values' units
    labels: np.ndarray  # (count, rows, cols) uint8 label id per voxel, 0 for none
    label_names: list[str]  # name per label id; id 0 is "unlabelled"
    wear: np.ndarray = field(init=False)  # burr steps each voxel has been inside the burr
    removed_mask: np.ndarray = field(init=False)  # bool: removed by the burr
    protected_hit: np.ndarray = field(init=False)  # bool: a protected voxel the burr touched

    def __post_init__(self) -> None:
        # np.full writes every page now: a lazily zeroed page (np.zeros) would be faulted in by
        # the first step that touches it, costing a control step ~10x its median
        self.wear = np.full(self.values.shape, 0, dtype=np.uint8)
        self._wear_per_step: float | None = None
        self.removed_mask = np.full(self.values.shape, False)
        self.protected_hit = np.full(self.values.shape, False)
        n, rows, cols = self.values.shape
        self.step = np.array([self.dimensions[0] / cols, self.dimensions[1] / rows, self.dimensions[2] / n])

    @property
    def voxel_volume(self) -> float:
        return float(np.prod(self.step))

    def index_of(self, p: np.ndarray) -> np.ndarray:
        """Continuous (x, y, z) voxel index of point ``p`` (volume frame): voxel i's centre is i."""
        return (np.asarray(p, dtype=float) + self.dimensions / 2) / self.step - 0.5

    def _steps_to_remove(self, wear: float) -> int:
        """Burr steps of ``wear`` (a fraction of a voxel each) that wear a voxel through: the
        counts are exact where adding fractions would round (0.025 forty times)."""
        if self._wear_per_step is None:
            self._wear_per_step = wear
            self._steps = max(1, int(np.ceil(1.0 / wear - 1e-9)))
            if self._steps > np.iinfo(self.wear.dtype).max:
                self.wear = self.wear.astype(np.uint16 if self._steps <= 65535 else np.uint32)
        elif wear != self._wear_per_step:
            raise ValueError("the wear per step is fixed for an EditableVolume")
        return self._steps

    def _block(self, p: np.ndarray, radius: float):
        """Index ranges (per axis x, y, z) of the voxels whose centre can lie within ``radius``
        of ``p``, clipped to the volume; None when the sphere misses it."""
        c = self.index_of(p)
        reach = radius / self.step
        lo = np.maximum(np.ceil(c - reach).astype(int), 0)
        shape = np.array(self.values.shape[::-1])
        hi = np.minimum(np.floor(c + reach).astype(int) + 1, shape)
        if np.any(hi <= lo):
            return None
        return lo, hi

    def burr_step(
        self, p: np.ndarray, radius: float, stiffness: float, wear: float, protected_ids: np.ndarray | None = None
    ) -> tuple[Contact, tuple[slice, slice, slice] | None, np.ndarray | None]:
        """One step of a burr of ``radius`` centred at ``p`` (volume frame): the contact force,
        then ``wear`` (0..1 of a voxel this step) on every tissue voxel inside it, and removal
        of those worn through. Returns the contact, the sub-block's slices and a mask of the
        voxels removed in it (None when nothing was), so callers can mark the surface."""
        nl = len(self.label_names)
        none = Contact(np.zeros(3), 0.0, np.zeros(nl, dtype=np.int64), np.zeros(nl, dtype=np.int64))
        rng = self._block(p, radius)
        if rng is None:
            return none, None, None
        (x0, y0, z0), (x1, y1, z1) = rng
        sl = (slice(z0, z1), slice(y0, y1), slice(x0, x1))
        vals = self.values[sl]
        # offsets burr centre -> voxel centre per axis (float32: a block's arrays are half the
        # bytes; µm over a few mm), broadcast to the block
        ox = ((np.arange(x0, x1) + 0.5) * self.step[0] - self.dimensions[0] / 2 - p[0]).astype(np.float32)
        oy = ((np.arange(y0, y1) + 0.5) * self.step[1] - self.dimensions[1] / 2 - p[1]).astype(np.float32)
        oz = ((np.arange(z0, z1) + 0.5) * self.step[2] - self.dimensions[2] / 2 - p[2]).astype(np.float32)
        d2 = (oz * oz)[:, None, None] + (oy * oy)[None, :, None] + (ox * ox)[None, None, :]
        inside = d2 < np.float32(radius * radius)
        tissue = inside & (vals > 0)
        if not tissue.any():
            return none, None, None
        solid = tissue & (vals >= self.iso)
        force, depth = np.zeros(3), 0.0
        if solid.any():
            kz, ky, kx = np.nonzero(solid)
            d = np.sqrt(d2[kz, ky, kx])
            pen = np.float32(radius) - d
            q = pen / np.maximum(d, np.float32(1e-12))
            # the gradient of the overlap energy sum(pen^2)/2: each voxel pushes the burr
            # away from its centre, by its penetration
            g = -np.array([q @ ox[kx], q @ oy[ky], q @ oz[kz]], dtype=float)
            depth = float(pen.max())
            gn = np.linalg.norm(g)
            if gn > 0:  # a penalty linear in the deepest penetration, along that gradient
                force = stiffness * depth * g / gn
        labs = self.labels[sl]
        touched = np.zeros(nl, dtype=np.int64)  # counted for the protected labels only (all a task reads)
        if protected_ids is not None and len(protected_ids):
            hit = tissue & np.isin(labs, protected_ids)
            if hit.any():
                touched = np.bincount(labs[hit], minlength=nl)[:nl]
                self.protected_hit[sl] |= hit
        removed = np.zeros(nl, dtype=np.int64)
        gone = None
        if wear > 0:
            w = self.wear[sl]
            steps = self._steps_to_remove(wear)
            np.add(w, tissue & (w < steps), out=w, casting="unsafe")  # (saturates at the count that removes)
            gone = tissue & (w >= steps)
            if gone.any():
                removed = np.bincount(labs[gone], minlength=nl)[:nl]
                vals[gone] = 0.0
                self.removed_mask[sl] |= gone
            else:
                gone = None
        return Contact(force, depth, touched, removed), sl, gone


class BlockSurface:
    """The iso-surface of a voxel array as one marching-cubes mesh per block of BLOCK³ cells.

    The array is padded with one empty voxel on every side (so the surface is closed where
    tissue meets the volume's faces); block b covers the cells between padded voxels
    b·BLOCK .. (b+1)·BLOCK, so neighbouring blocks share a plane of voxels but no cell and
    no triangle."""

    def __init__(self, values: np.ndarray, dimensions: np.ndarray, level: float):
        self.level = float(level)
        self.dimensions = np.asarray(dimensions, dtype=float)
        n, rows, cols = values.shape
        self.spacing = np.array([self.dimensions[2] / n, self.dimensions[1] / rows, self.dimensions[0] / cols])
        self.padded = np.pad(values, 1)  # the values' own type: uint8 slices stay a quarter of float32
        cells = np.array(self.padded.shape) - 1
        self.blocks = tuple(int(c) for c in -(-cells // BLOCK))
        self.meshes: dict[tuple[int, int, int], tuple[np.ndarray, np.ndarray]] = {}
        self.dirty: set[tuple[int, int, int]] = set()
        self.remeshed = 0  # blocks re-meshed since the start (the full build not counted)
        for b in np.ndindex(*self.blocks):
            self._mesh(b)

    def _mesh(self, b: tuple[int, int, int]) -> None:
        from skimage.measure import marching_cubes

        lo = np.array(b) * BLOCK
        sub = self.padded[lo[0] : lo[0] + BLOCK + 1, lo[1] : lo[1] + BLOCK + 1, lo[2] : lo[2] + BLOCK + 1]
        if min(sub.shape) < 2 or not (sub.max() >= self.level > sub.min()):
            self.meshes.pop(b, None)
            return
        verts, faces, _, _ = marching_cubes(sub, level=self.level, spacing=tuple(self.spacing))
        verts = verts + lo * self.spacing  # padded (slice, row, column) index space, in metres
        # padded index q is voxel q-1, centred at (q - 1/2)·step from the box's corner
        xyz = verts[:, ::-1] - 0.5 * self.spacing[::-1] - self.dimensions / 2
        self.meshes[b] = (xyz.astype(np.float32), faces.astype(np.int32))

    def mark(self, sl: tuple[slice, slice, slice], removed: np.ndarray) -> None:
        """Copy the edited voxels ``removed`` (a mask over the sub-block ``sl`` of the unpadded
        array) to zero here, and mark every block whose cells they are a corner of."""
        self.padded[
            sl[0].start + 1 : sl[0].stop + 1, sl[1].start + 1 : sl[1].stop + 1, sl[2].start + 1 : sl[2].stop + 1
        ][removed] = 0
        # the removed voxels' box, in padded indices: padded voxel q is a corner of cells q-1 and q
        lo, hi = [], []
        for axis, s in enumerate(sl):
            other = tuple(a for a in range(3) if a != axis)
            hit = np.flatnonzero(removed.any(axis=other))
            lo.append(s.start + 1 + hit[0])
            hi.append(s.start + 1 + hit[-1])
        lo = np.maximum((np.array(lo) - 1) // BLOCK, 0)
        hi = np.minimum(np.array(hi) // BLOCK, np.array(self.blocks) - 1)
        for b in np.ndindex(*(hi - lo + 1)):
            self.dirty.add(tuple(int(v) for v in lo + np.array(b)))

    def update(self) -> int:
        """Re-mesh the marked blocks; returns how many."""
        n = len(self.dirty)
        for b in self.dirty:
            self._mesh(b)
        self.remeshed += n
        self.dirty.clear()
        return n

    @property
    def triangles(self) -> int:
        return sum(len(f) for _, f in self.meshes.values())

    def write_stl(self, path) -> None:
        """The whole surface as a binary STL, written block by block (the 512³ skull's surface,
        millions of triangles, never whole in memory), atomically."""
        import os
        import tempfile
        from pathlib import Path

        path = Path(path)
        rec = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(b"adfkit drilled surface".ljust(80, b" "))
                fh.write(np.uint32(self.triangles).tobytes())
                for b in sorted(self.meshes):
                    v, f = self.meshes[b]
                    tri = v[f]
                    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
                    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
                    out = np.zeros(len(f), dtype=rec)
                    out["normal"], out["v"] = n, tri
                    fh.write(out.tobytes())
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            raise

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """The whole surface: (vertices (n, 3) metres in the volume frame, faces (m, 3))."""
        verts, faces, base = [], [], 0
        for b in sorted(self.meshes):
            v, f = self.meshes[b]
            verts.append(v)
            faces.append(f + base)
            base += len(v)
        if not verts:
            return np.zeros((0, 3), dtype=np.float32), np.zeros((0, 3), dtype=np.int64)
        return np.concatenate(verts), np.concatenate(faces)


__all__ = ["BLOCK", "BlockSurface", "Contact", "EditableVolume"]
