"""A volume's slice stack found in a folder (adfkit.geometry.volume_folder, what the add-on's
Add volume operator reads): the drilling sample's slices, and every kind of folder that does
not hold one clean stack refused with a located reason and a hint."""

from __future__ import annotations

import pytest
from conftest import ROOT

from adfkit.diagnostics import AdfError
from adfkit.geometry.volume_folder import find_slices


def _stack(folder, names, sizes=None):
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    for i, n in enumerate(names):
        w = (sizes or {}).get(n, 8)
        Image.new("L", (w, w), 255 if i % 2 else 0).save(folder / n)
    return folder


def test_the_drilling_slices_are_one_stack():
    s = find_slices(ROOT / "sample_scenes" / "drilling" / "slices")
    assert (s.prefix, s.format, s.count, s.width, s.height) == ("bone_", "png", 48, 48, 48)
    assert s.names()[-1] == "bone_47.png"


@pytest.mark.parametrize(
    "names, prefix, count",
    [
        ([f"plane00{i}.png" for i in range(12)], "plane00", 12),  # the drilling projects' naming
        ([f"s_{i:03d}.png" for i in range(48)], "s_0", 48),  # padded within count's two digits
        ([f"s_{i:03d}.png" for i in range(3)], "s_00", 3),
    ],
)
def test_leading_zeros_are_read_as_ambf_reads_them(tmp_path, names, prefix, count):
    from adfkit.geometry.volume_slices import find_slice_files

    folder = _stack(tmp_path / "s", names)
    s = find_slices(folder)
    assert (s.prefix, s.count, s.files) == (prefix, count, names)
    assert [p.name for p in find_slice_files(folder, s.prefix, "png", s.count).files] == names  # AMBF's rule agrees
    assert find_slices(folder, prefix).files == names


def test_a_prefix_picks_one_stack_of_several(tmp_path):
    folder = _stack(tmp_path / "s", ["a_0.png", "a_1.png", "b_0.png", "notes.txt.png"])
    (folder / "readme.txt").write_text("not a slice")
    s = find_slices(folder, "a_")
    assert (s.prefix, s.count) == ("a_", 2)


@pytest.mark.parametrize(
    "names, sizes, prefix, rule, says",
    [
        ([], None, None, "volume-no-slices", "no slice images named <prefix><index>.<format>"),
        (["ct_0.png"], None, "bone_", "volume-no-slices", "no slice images named bone_<index>"),
        (["ct_0.png", "ct_1.png", "ct_3.png", "ct_4.png"], None, None, "volume-slice-gap", "gaps: ct_2.png missing"),
        (["ct_1.png", "ct_2.png"], None, None, "volume-slice-gap", "gaps: ct_0.png missing (2 slices between 1 and 2)"),
        (
            ["ct_0.png", "ct_1.png", "ct_2.png"],
            {"ct_2.png": 4},
            None,
            "volume-slice-size",
            "ct_0.png is 8x8, ct_2.png is 4x4",
        ),
        (["ct_0.png", "ct_01.png", "ct_2.png"], None, None, "volume-slice-names", "mixes widths of numbering"),
        (["ct_000.png", "ct_001.png", "ct_003.png"], None, None, "volume-slice-gap", "gaps: ct_002.png missing"),
        (
            ["a_0.png", "a_1.png", "b_0.png"],
            None,
            None,
            "volume-slice-names",
            "several slice stacks: a_<index>.png (2 files)",
        ),
    ],
)
def test_a_folder_that_is_not_one_clean_stack_is_refused_with_a_reason(tmp_path, names, sizes, prefix, rule, says):
    folder = _stack(tmp_path / "slices", names, sizes)
    with pytest.raises(AdfError) as exc:
        find_slices(folder, prefix)
    (d,) = exc.value.diagnostics
    assert d.rule == rule and says in d.message, d.message
    assert d.message.startswith(str(folder)) and d.location.file == str(folder) and d.hint


def test_a_slice_that_is_not_an_image_and_a_file_for_a_folder(tmp_path):
    folder = _stack(tmp_path / "slices", ["ct_0.png"])
    (folder / "ct_1.png").write_bytes(b"not a png")
    with pytest.raises(AdfError) as exc:
        find_slices(folder)
    assert exc.value.diagnostics[0].rule == "volume-slice-unreadable" and "ct_1.png" in exc.value.diagnostics[0].message
    with pytest.raises(AdfError) as exc:
        find_slices(folder / "ct_0.png")
    assert exc.value.diagnostics[0].rule == "volume-folder"
