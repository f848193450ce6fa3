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
