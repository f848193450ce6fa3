# splat.render and splat.Scene against the CLI: the same pixels bit for bit, the same
# one-line error messages; statistics; progress and cancellation.
import json

import numpy as np
import pytest

import splat
from conftest import same_bits

SPEC = "synthetic:phantom:24"
MODES = ["dvr", "mip", "xray", "iso"]
RENDERERS = ["axis", "sheet", "reference"]


def cli_render(cli, tmp, *flags):
    out = tmp / "cli.exr"
    cli("render", SPEC, *flags, "-o", out)
    return splat.read_image(str(out))


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("renderer", RENDERERS)
def test_render_equals_cli_exr_bit_for_bit(cli, tmp, phantom, renderer, mode):
    kw = dict(renderer=renderer, mode=mode, size=(40, 32), azimuth=33.5, elevation=-12.25,
              slab=0.5, ref_step=0.5)
    flags = ["--renderer", renderer, "--mode", mode, "--size", "40x32", "--azimuth", "33.5",
             "--elevation", "-12.25", "--slab", "0.5", "--ref-step", "0.5"]
    if mode == "dvr":
        kw.update(tf="ct-bone", shade=True, classify="post")
        flags += ["--tf", "ct-bone", "--shade", "--classify", "post"]
    image = splat.render(phantom, **kw)
    assert image.shape == (32, 40, 4) and image.dtype == np.float32
    assert image[..., 3].max() > 0  # something is drawn
    assert same_bits(image, cli_render(cli, tmp, *flags))


def test_free_camera_background_and_quality_knobs_equal_cli(cli, tmp, phantom):
    image = splat.render(phantom, size=(36, 36), eye=(60.0, -40.0, 30.0), look_at=(11.5, 11.5, 11.5),
                         up=(0, 0, 1), background=(0.1, 0.2, 0.3, 1.0), early_termination=0.01,
                         tile_size=16, threads=2, kernel="bspline", projection="perspective")
    ref = cli_render(cli, tmp, "--size", "36x36", "--eye", "60,-40,30", "--look-at",
                     "11.5,11.5,11.5", "--up", "0,0,1", "--background", "0.1,0.2,0.3,1",
                     "--early-termination", "0.01", "--tile-size", "16", "--threads", "2",
                     "--kernel", "bspline", "--projection", "perspective")
    assert same_bits(image, ref)


def test_transfer_function_object_equals_cli_json_file(cli, tmp, phantom):
    points = np.array([[0.0, 0, 0, 0, 0], [0.9, 1, 0.5, 0.2, 0.05], [2.0, 1, 1, 1, 0.6]])
    tf = splat.TransferFunction(points, unit_distance=2.0, name="mine")
    path = tmp / "tf.json"
    path.write_text(tf.to_json())
    assert same_bits(splat.render(phantom, tf=tf, size=(32, 32)),
                     cli_render(cli, tmp, "--tf", path, "--size", "32x32"))
    # an N x 5 array is taken as the control points
    assert same_bits(splat.render(phantom, tf=points.tolist(), size=(32, 32), renderer="sheet"),
                     splat.render(phantom, tf=splat.TransferFunction(points), size=(32, 32),
                                  renderer="sheet"))


def test_ct_in_hounsfield_gets_the_clis_default_preset(cli, tmp):
    ct = splat.load("synthetic:ct-phantom:24")
    out = tmp / "ct.exr"
    cli("render", "synthetic:ct-phantom:24", "--size", "32x32", "-o", out)
    assert same_bits(splat.render(ct, size=(32, 32)), splat.read_image(str(out)))


def test_scene_reuses_classification_and_equals_render(phantom):
    scene = splat.Scene(phantom, tf="ct-bone", size=(32, 32))
    for renderer in RENDERERS:
        for az in (0.0, 45.0):
            a = scene.render(renderer=renderer, azimuth=az)
            b = splat.render(phantom, tf="ct-bone", size=(32, 32), renderer=renderer, azimuth=az)
            assert same_bits(a, b)
    with pytest.raises(splat.InputError, match="classif"):
        scene.render(classify="post")  # a per-scene knob needs a new Scene


def test_stats_dict(phantom):
    image, stats = splat.render(phantom, size=(32, 32), return_stats=True)
    assert stats["voxels"] == 24 ** 3
    assert 0 < stats["splats"] <= stats["voxels"]
    assert stats["sheet_axis"] in (0, 1, 2) and stats["milliseconds"] > 0
    _, stats = splat.render(phantom, size=(32, 32), renderer="reference", return_stats=True)
    assert stats["sheet_axis"] == -1 and stats["reference_step"] > 0


def test_rotate_yields_the_views_of_splat_rotate(cli, tmp, phantom):
    frames = list(splat.rotate(phantom, 6, from_=0, to=90, size=(24, 24)))
    assert len(frames) == 6
    cli("rotate", SPEC, "--frames", 6, "--from", 0, "--to", 90, "--size", "24x24", "--format",
        "exr", "-o", tmp / "rot", "-q")
    files = sorted((tmp / "rot").glob("*.exr"))
    assert len(files) == 6
    for f, image in zip(files, frames):
        assert same_bits(image, splat.read_image(str(f)))


def test_iso_depth_is_the_first_hit_distance(phantom):
    scene = splat.Scene(phantom, mode="iso", iso_level="0.5n", size=(24, 24))
    depth = scene.iso_depth(renderer="reference")
    assert depth.shape == (24, 24)
    hit = np.isfinite(depth)
    assert hit.any() and (~hit).any() and (depth[hit] > 0).all()


@pytest.mark.parametrize("kw,flags", [
    (dict(size=(0, 5)), ["--size", "0x5"]),
    (dict(slab=0.0), ["--slab", "0"]),
    (dict(mode="volume"), ["--mode", "volume"]),
    (dict(renderer="gpu"), ["--renderer", "gpu"]),
    (dict(tf="no-such-preset"), ["--tf", "no-such-preset"]),
    (dict(background=(2, 0, 0)), ["--background", "2,0,0"]),
    (dict(tile_size=4), ["--tile-size", "4"]),
    (dict(look_at=(1, 2, 3)), ["--look-at", "1,2,3"]),
])
def test_errors_carry_the_clis_one_line_message(cli, tmp, phantom, kw, flags):
    p = cli("render", SPEC, *flags, "-o", tmp / "x.exr", check=False)
    assert p.returncode == 2
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith("splat: error: ")
    with pytest.raises(splat.InputError) as e:
        splat.render(phantom, **kw)
    assert isinstance(e.value, ValueError) and isinstance(e.value, splat.Error)
    assert str(e.value) == line[len("splat: error: "):]
    assert not (tmp / "x.exr").exists()


def test_unknown_keyword_is_named(phantom):
    with pytest.raises(splat.InputError, match="unknown keyword 'azimut'"):
        splat.render(phantom, azimut=3)


def test_every_cli_render_option_is_a_keyword(cli):
    text = cli("render", "--help").stdout
    keywords = set(splat.render_options())
    for flag in ["--tf", "--size", "--azimuth", "--elevation", "--mode", "--renderer",
                 "--classify", "--slab", "--eye", "--look-at", "--up", "--early-termination",
                 "--ref-step", "--ref-tolerance", "--tile-size", "--lod", "--threads",
                 "--kernel", "--sigma", "--radius", "--shade", "--clip-plane", "--crop"]:
        assert flag in text
        assert flag[2:].replace("-", "_") in keywords
    assert "background_value" in splat.load_options()


def test_progress_is_called_and_false_cancels(phantom):
    calls = []
    splat.render(phantom, size=(64, 64), renderer="reference",
                 progress=lambda d, t, w: calls.append((d, t, w)))
    assert [c[0] for c in calls] == list(range(1, 65)) and calls[0][1:] == (64, "rows")
    with pytest.raises(splat.Cancelled):
        splat.render(phantom, size=(64, 64), tile_size=16, renderer="reference",
                     progress=lambda d, t, w: d < 3)
    with pytest.raises(ZeroDivisionError):
        splat.render(phantom, size=(64, 64), progress=lambda d, t, w: 1 / 0)
    with pytest.raises(splat.InputError, match="callable"):
        splat.render(phantom, progress=3)


def test_compare_equals_cli_compare(cli, tmp, phantom):
    a = splat.render(phantom, size=(32, 32), renderer="axis")
    b = splat.render(phantom, size=(32, 32), renderer="reference")
    splat.write_image(str(tmp / "a.exr"), a)
    splat.write_image(str(tmp / "b.exr"), b)
    cli("compare", tmp / "a.exr", tmp / "b.exr", "--json", tmp / "c.json", "--fail-above",
        "flip=1")
    ref = json.loads((tmp / "c.json").read_text())
    got = splat.compare(a, b)
    for key in ["rmse", "psnr", "max_abs", "mean_abs_foreground", "foreground_pixels", "flip"]:
        assert got[key] == pytest.approx(ref[key], rel=1e-12), key
    same = splat.compare(a, a)
    assert same["rmse"] == 0 and same["flip"] == 0
    with pytest.raises(splat.InputError, match="size"):
        splat.compare(a, b[:16])
