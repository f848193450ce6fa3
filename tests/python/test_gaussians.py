# Gaussian scenes from Python (splat/gaussians.h): arrays in and out, .ply round trip, the four
# renderers, and one-line errors.
import numpy as np
import pytest

import splat


def test_arrays_round_trip_and_render(tmp_path):
    g = splat.load_gaussians("gaussians:pop")
    assert len(g) == 2 and g.sh_degree == 0
    h = splat.Gaussians(g.means, g.scales, g.rotations, g.opacities, g.sh)
    assert np.array_equal(h.means, g.means)
    a = splat.render_gaussians(g, width=33, height=33)
    b = splat.render_gaussians(h, width=33, height=33)
    assert a.shape == (33, 33, 4) and np.array_equal(a, b)
    path = tmp_path / "pop.ply"
    h.write(str(path))
    k = splat.load_gaussians(str(path))
    assert np.array_equal(k.sh, g.sh)
    assert np.allclose(k.opacities, 0.8, atol=1e-6)


def test_lone_gaussian_centre_alpha_in_every_renderer():
    # Opacity 0.6, white: the centre pixel's alpha is 0.6 in all four renderers.
    g = splat.Gaussians(np.zeros((1, 3)), [[0.3, 0.5, 0.2]], [[1, 0, 0, 0]], [0.6],
                        np.full((1, 1, 3), (1 - 0.5) / 0.28209479177387814))
    for r in ["3dgs", "3dgs-pixel", "sheet", "reference"]:
        img = splat.render_gaussians(g, renderer=r, width=31, height=31)
        assert img[15, 15, 3] == pytest.approx(0.6, abs=1e-6), r
        assert img[15, 15, 0] == pytest.approx(0.6, abs=1e-6), r


def test_bad_input_is_one_line(tmp_path):
    g = splat.load_gaussians("gaussians:pop")
    with pytest.raises(splat.InputError, match="shape"):
        splat.Gaussians(g.means, g.scales[:1], g.rotations, g.opacities, g.sh)
    with pytest.raises(splat.InputError, match="unknown Gaussian renderer"):
        splat.render_gaussians(g, renderer="axis")
    bad = tmp_path / "a.ply"
    bad.write_text("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n")
    with pytest.raises(splat.InputError, match="ASCII PLY"):
        splat.load_gaussians(str(bad))
    with pytest.raises(splat.FileError):
        splat.load_gaussians(str(tmp_path / "missing.ply"))


def _pop_arrays():
    g = splat.load_gaussians("gaussians:pop")
    return [np.ascontiguousarray(a, dtype=np.float32)
            for a in (g.means, g.scales, g.rotations, g.opacities, g.sh)]


def test_float32_contiguous_arrays_are_borrowed_not_copied():
    means, scales, rotations, opacities, sh = _pop_arrays()
    g = splat.Gaussians(means, scales, rotations, opacities, sh)
    assert g.borrowed
    before = splat.render(g, size=(32, 32))
    # The scene reads the arrays' memory: moving a mean in the array moves the Gaussian.
    means[0, 2] += 0.5
    after = splat.render(g, size=(32, 32))
    assert not np.array_equal(before, after)
    assert g.means[0, 2] == means[0, 2]
    # The same scene copied from float64 or strided arrays renders the same image.
    h = splat.Gaussians(means.astype(np.float64), np.asfortranarray(scales), rotations,
                        opacities.tolist(), sh)
    assert not h.borrowed
    assert np.array_equal(splat.render(h, size=(32, 32)), after)


def test_render_and_scene_take_gaussian_scenes(tmp_path):
    g = splat.load_gaussians("gaussians:pop")
    ref = splat.render_gaussians(g, renderer="sheet", width=32, height=24, azimuth=30, slab=0.1)
    img = splat.render(g, renderer="sheet", size=(32, 24), azimuth=30, slab=0.1)
    assert np.array_equal(img, ref)
    path = tmp_path / "pop.ply"
    g.write(str(path))
    assert np.array_equal(splat.render(str(path), size=(32, 24)),
                          splat.render_gaussians(g, width=32, height=24))
    scene = splat.Scene("gaussians:pop", size=(32, 24))
    assert scene.splat_count == 2
    assert np.array_equal(scene.render(renderer="sheet", azimuth=30, slab=0.1), ref)
    frames = list(scene.rotate(3, from_=0, to=20))
    assert len(frames) == 3
    assert np.array_equal(frames[2], splat.render(g, size=(32, 24), azimuth=20))
    with pytest.raises(splat.InputError, match="unknown Gaussian renderer"):
        splat.render(g, renderer="axis")


def test_popping_of_a_gaussian_scene():
    r = splat.popping(splat.load_gaussians("gaussians:pop"), from_=-5.5, to=5.5, step=1,
                      size=(32, 32), slab=0.05, ref_tolerance=1e-5, refine=4, no_flip=True)
    assert r.renderers == ["3dgs", "3dgs-pixel", "sheet", "reference"]
    assert r.predicted_name == "order swap"
    assert list(r.predicted_switches) == pytest.approx([0.0], abs=1e-8)
    assert sorted(e["renderer"] for e in r.events) == ["3dgs", "3dgs-pixel"]
    assert all(e["predicted"] and abs(e["refined_slope"]) < 0.2 for e in r.events)
    with pytest.raises(splat.InputError, match="unknown Gaussian renderer"):
        splat.popping("gaussians:pop", renderers="3dgs,axis")
