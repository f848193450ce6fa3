# splat.Volume from NumPy arrays: index order, zero-copy wrapping, the documented conversions,
# every bad-array case; splat.load and splat.from_nibabel against each other.
import subprocess

import numpy as np
import pytest

import splat
from conftest import CH2, SRC, same_bits


def test_index_order_is_zyx_and_spacing_xyz():
    a = np.arange(4 * 5 * 6, dtype=np.float32).reshape(4, 5, 6)  # [z, y, x]
    v = splat.Volume(a, spacing=(0.5, 2.0, 3.0), origin=(1, 2, 3))
    assert v.dims == (6, 5, 4) and v.shape == (4, 5, 6)
    assert v.spacing == (0.5, 2.0, 3.0) and v.origin == (1.0, 2.0, 3.0)
    assert v.center == (1 + 0.5 * 2.5, 2 + 2.0 * 2, 3 + 3.0 * 1.5)
    assert np.array_equal(v.array, a)
    assert v.value_range == (0.0, float(a.max()))
    assert np.array_equal(v.affine, [[0.5, 0, 0, 1], [0, 2, 0, 2], [0, 0, 3, 3], [0, 0, 0, 1]])
    assert np.array_equal(v.orientation, np.eye(3))
    # nibabel's [x, y, z] order: the transpose
    w = splat.Volume(a.T, spacing=(0.5, 2.0, 3.0), order="xyz")
    assert w.dims == v.dims and np.array_equal(w.array, a)


def test_float32_contiguous_is_wrapped_without_copy():
    a = np.random.default_rng(1).random((8, 9, 10), dtype=np.float32)
    v = splat.Volume(a)
    assert np.shares_memory(v.array, a)
    assert v.borrowed
    assert not v.array.flags.writeable


@pytest.mark.parametrize("dtype", [np.uint8, np.int16, np.uint16])
def test_typed_arrays_are_wrapped_without_copy(dtype):
    a = (np.arange(6 * 7 * 8) % 100).astype(dtype).reshape(6, 7, 8)
    v = splat.Volume(a)
    assert np.shares_memory(v.array, a) and v.dtype == np.dtype(dtype).name
    assert np.array_equal(v.array, a)
    f = splat.Volume(a.astype(np.float32))
    assert same_bits(splat.render(v, size=(24, 24)), splat.render(f, size=(24, 24)))


def test_changing_the_array_and_rewrapping_changes_the_image():
    a = np.zeros((16, 16, 16), dtype=np.float32)
    a[4:12, 4:12, 4:12] = 1.0
    v = splat.Volume(a)
    before = splat.render(v, size=(24, 24), mode="mip")
    a[4:12, 4:12, 4:12] = 0.5  # the volume sees the caller's memory
    assert v.array.max() == 0.5
    after = splat.render(splat.Volume(a), size=(24, 24), mode="mip")
    assert not same_bits(before, after)
    # the same pixels as a converted copy of the changed data
    assert same_bits(after, splat.render(splat.Volume(a.astype(np.float64)), size=(24, 24),
                                         mode="mip"))


@pytest.mark.parametrize("make", [
    lambda: np.arange(24, dtype=np.float64).reshape(2, 3, 4),      # float64: rounded
    lambda: np.arange(24, dtype=np.int32).reshape(2, 3, 4),        # int32: converted
    lambda: (np.arange(24) % 2 == 0).reshape(2, 3, 4),             # bool: 0 and 1
    lambda: np.arange(48, dtype=np.float32).reshape(2, 3, 8)[:, :, ::2],  # non-contiguous
    lambda: np.asfortranarray(np.arange(24, dtype=np.float32).reshape(2, 3, 4)),
    lambda: np.arange(24, dtype=np.float32).reshape(2, 3, 4).tolist(),    # nested lists
])
def test_other_arrays_are_converted_to_float32(make):
    a = make()
    v = splat.Volume(a)
    assert v.dtype == "float32" and not v.borrowed
    assert np.array_equal(v.array, np.asarray(a, dtype=np.float32))


@pytest.mark.parametrize("array,message", [
    (np.zeros((4, 4), np.float32), "must be 3-D"),
    (np.zeros((2, 2, 2, 2), np.float32), "must be 3-D"),
    (np.zeros((0, 4, 4), np.float32), "no samples"),
    (np.zeros((3, 3, 3), np.complex64), "not a real number type"),
    (np.array([[["a"]]]), "not a real number type"),
    (np.empty((2, 2, 2), dtype=object), "not a real number type"),
    (np.broadcast_to(np.float32(0), (1, 1, 70000)), "longer than 65535"),
    (np.broadcast_to(np.float32(0), (60000, 60000, 2)), "voxel"),
])
def test_bad_arrays_are_refused_with_one_line(array, message):
    with pytest.raises(splat.InputError, match=message) as e:
        splat.Volume(array)
    assert isinstance(e.value, ValueError) and "\n" not in str(e.value)


def test_non_finite_samples_are_refused_or_zeroed():
    a = np.ones((3, 4, 5), np.float32)
    a[1, 2, 3] = np.nan
    a[2, 0, 0] = np.inf
    with pytest.raises(splat.InputError, match=r"2 NaN/Inf samples \(first at \[z, y, x\] = \[1, 2, 3\]\)"):
        splat.Volume(a)
    v = splat.Volume(a, nan_policy="zero")
    assert v.array[1, 2, 3] == 0 and v.array[2, 0, 0] == 0 and np.isfinite(a).sum() == 58
    assert any("2 NaN/Inf samples replaced by 0" in n for n in v.notes)


@pytest.mark.parametrize("kw,message", [
    (dict(spacing=(1, 0, 1)), "spacing"),
    (dict(spacing=(1, 1)), "3 numbers"),
    (dict(origin=(0, np.nan, 0)), "finite"),
    (dict(order="yxz"), "order"),
    (dict(nan_policy="ignore"), "nan_policy"),
    (dict(background_value=np.inf), "background_value"),
])
def test_bad_geometry_and_options(kw, message):
    with pytest.raises(splat.InputError, match=message):
        splat.Volume(np.ones((2, 2, 2), np.float32), **kw)


def test_background_value_default_is_the_loaders_rule():
    a = np.full((8, 8, 8), -1000.0, np.float32)
    a[2:6, 2:6, 2:6] = 40
    assert splat.Volume(a).background_value == -1000
    assert splat.Volume(a, background_value=-1024).background_value == -1024


def test_array_outlives_the_wrapped_volume():
    v = splat.Volume(np.arange(27, dtype=np.float32).reshape(3, 3, 3) + 1)
    view = v.array
    del v
    assert view.sum() == sum(range(1, 28))


def test_load_options_and_errors(cli, tmp):
    v = splat.load("synthetic:blob:16", background_value=0.25)
    assert v.background_value == 0.25 and v.shape == (16, 16, 16)
    with pytest.raises(splat.FileError) as e:
        splat.load(str(tmp / "missing.nii"))
    assert isinstance(e.value, OSError)
    p = cli("info", tmp / "missing.nii", check=False)
    assert str(e.value) == p.stderr.strip().splitlines()[-1][len("splat: error: "):]
    with pytest.raises(splat.InputError, match="nan-policy"):
        splat.load("synthetic:blob:8", nan_policy="maybe")


@pytest.mark.skipif(not CH2.exists(), reason="mricron-data (ch2.nii.gz) not installed")
def test_nibabel_array_with_its_affine_equals_splat_load():
    nib = pytest.importorskip("nibabel")
    img = nib.load(str(CH2))
    a, b = splat.from_nibabel(img), splat.load(str(CH2))
    assert a.dims == b.dims and a.spacing == b.spacing and a.origin == b.origin
    assert np.array_equal(a.array, b.array)
    assert a.background_value == b.background_value
    # zero-copy: nibabel's [x, y, z] uint8 array in Fortran order is [z, y, x] in C order
    assert a.borrowed


def test_byte_swapped_and_nan_zeroed_arrays_are_copies():
    a = np.arange(24, dtype=">f4").reshape(2, 3, 4)
    v = splat.Volume(a)
    assert not v.borrowed and v.dtype == "float32" and np.array_equal(v.array, a)
    b = np.ones((2, 2, 2), np.float32)
    b[0, 0, 0] = np.nan
    w = splat.Volume(b, nan_policy="zero")
    assert not w.borrowed and np.isnan(b[0, 0, 0])  # the caller's array is untouched


def test_flipped_and_permuted_affine_equals_splat_load(tmp):
    nib = pytest.importorskip("nibabel")
    data = np.random.default_rng(2).integers(0, 1000, (7, 5, 6)).astype(np.int16)
    affine = np.array([[0, 0, -1.5, 40], [2.0, 0, 0, -10], [0, 0.75, 0, 3], [0, 0, 0, 1]])
    img = nib.Nifti1Image(data, affine)
    path = tmp / "flipped.nii.gz"
    nib.save(img, str(path))
    a, b = splat.from_nibabel(nib.load(str(path))), splat.load(str(path))
    assert a.dims == b.dims == (6, 7, 5)
    assert a.spacing == b.spacing and a.origin == pytest.approx(b.origin, abs=1e-12)
    assert np.array_equal(a.array, b.array)


def test_time_step_of_a_4d_nifti_equals_nibabels(tmp):
    nib = pytest.importorskip("nibabel")
    data = (100 + np.random.default_rng(3).integers(0, 1000, (6, 5, 4, 7))).astype(np.int16)
    path = tmp / "series.nii.gz"
    nib.save(nib.Nifti1Image(data, np.diag([0.5, 2.0, 1.5, 1.0])), str(path))
    for t in (0, 3, 6):
        v = splat.load(str(path), time=t)
        # nibabel's [x, y, z] is splat's [z, y, x] transposed
        assert np.array_equal(v.array, data[..., t].T.astype(np.float32))
    with pytest.raises(splat.InputError, match="time step 7 is out of range"):
        splat.load(str(path), time=7)


def test_zarr_level_is_the_level_of_detail_of_the_view(tmp):
    # tests/sparse/make_sparse_data.py writes pyramid.zarr (32^3 voxels of 0.5, levels 1 and
    # 2 the exact 2x2x2 means) and pyramid_1.nii.gz (level 1 as NIfTI).
    p = subprocess.run(["/usr/bin/python3", str(SRC / "tests" / "sparse" / "make_sparse_data.py"),
                        str(tmp)], capture_output=True, text=True)
    if p.returncode == 77:
        pytest.skip(p.stderr.strip())
    assert p.returncode == 0, p.stderr
    zarr = str(tmp / "pyramid.zarr")
    # --lod 2: the first level whose voxel covers 2 pixels (a level-0 voxel: 0.018 W pixels).
    levels = [splat.zarr_level(zarr, size=f"{n}x{n}", lod=2) for n in (256, 64, 32, 16)]
    assert levels == [0, 1, 2, 2]
    assert splat.zarr_level(zarr, size="16x16") == 0  # level of detail off
    assert splat.zarr_level(zarr, size="16x16", lod="auto", mode="xray") == 1
    v = splat.load(zarr, zarr_level=splat.zarr_level(zarr, size="64x64", lod=2))
    n = splat.load(str(tmp / "pyramid_1.nii.gz"))
    assert v.dims == n.dims and v.spacing == n.spacing and v.origin == n.origin
    assert np.array_equal(v.array, n.array)
