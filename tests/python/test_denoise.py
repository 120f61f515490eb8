# penumbra.denoise and denoise=True: the result's denoised beauty equals the denoiser run on
# its own halves arrays and on the EXR it writes (read back by oiiotool), the main layer follows
# denoise_main, and bad arrays, settings and files are refused with the element named.
import numpy as np
import pytest

import penumbra
from test_files import channels, pixels

SIZE = dict(width=48, height=32)


def halves(aovs):
    return dict(color=np.stack([aovs["even"], aovs["odd"]]),
                albedo=np.stack([aovs["even_albedo"], aovs["odd_albedo"]]),
                normal=np.stack([aovs["even_N"], aovs["odd_N"]]),
                depth=np.stack([aovs["even_Z"], aovs["odd_Z"]]))


def test_denoised_render_equals_the_denoiser_on_its_halves(default_scene):
    r = default_scene.render(integrator="path", spp=8, denoise=True, **SIZE)
    assert r.noisy.shape == r.denoised.shape == (32, 48, 4)
    np.testing.assert_array_equal(r.beauty, r.denoised)
    np.testing.assert_array_equal(r.denoised[..., 3], r.noisy[..., 3])
    out = penumbra.denoise(**halves(r.aovs), threads=1)
    assert out.shape == (32, 48, 3) and out.dtype == np.float32
    np.testing.assert_array_equal(out, r.denoised[..., :3])
    cb = penumbra.denoise(**halves(r.aovs), method="cross_bilateral")
    assert cb.shape == out.shape and not np.array_equal(cb, out)
    # The halves average to the noisy beauty (4 even and 4 odd samples).
    np.testing.assert_allclose((r.aovs["even"] + r.aovs["odd"]) / 2, r.noisy[..., :3], atol=1e-5)
    # Denoising smooths: neighbouring pixels differ less than in the noisy image.
    assert np.abs(np.diff(r.denoised[..., :3], axis=1)).mean() < 0.5 * np.abs(np.diff(r.noisy[..., :3], axis=1)).mean()


def test_noisy_main_keeps_the_render_as_the_beauty(default_scene):
    r = default_scene.render(integrator="path", spp=4, denoise=True, denoise_main="noisy", **SIZE)
    plain = default_scene.render(integrator="path", spp=4, **SIZE)
    np.testing.assert_array_equal(r.beauty, plain.beauty)
    np.testing.assert_array_equal(r.noisy, plain.beauty)
    assert not np.array_equal(r.denoised, plain.beauty)
    assert plain.noisy is None and plain.denoised is None


def test_files_denoised_by_the_module_match_the_render(tmp_path, default_scene):
    r = default_scene.render(integrator="path", spp=4, aovs=["halves"], **SIZE)
    r.write_exr(tmp_path / "noisy.exr", half=False)
    assert {"even.R", "odd_albedo.G", "even_N.Z", "odd_Z.Z"} <= set(channels(tmp_path / "noisy.exr"))
    penumbra.denoise(tmp_path / "noisy.exr", tmp_path / "denoised.exr")
    names = channels(tmp_path / "denoised.exr")
    assert {"noisy.R", "noisy.A"} <= set(names)
    px = pixels(tmp_path / "denoised.exr", 48, 32)
    expected = penumbra.denoise(**halves(r.aovs))
    # oiiotool prints 9 decimals: equal within that rounding.
    close = dict(rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(px[..., :3], expected, **close)
    np.testing.assert_allclose(px[..., names.index("noisy.G")], r.beauty[..., 1], **close)
    with pytest.raises(penumbra.InputError, match="already denoised"):
        penumbra.denoise(tmp_path / "denoised.exr", tmp_path / "again.exr")
    plain = default_scene.render(integrator="path", spp=2, **SIZE)
    plain.write_exr(tmp_path / "plain.exr")
    with pytest.raises(penumbra.InputError, match="plain.exr: lacks the layers the denoiser needs: even"):
        penumbra.denoise(tmp_path / "plain.exr", tmp_path / "out.exr")
    assert not (tmp_path / "out.exr").exists()


def test_bad_arrays_and_settings_are_refused(default_scene):
    r = default_scene.render(integrator="path", spp=4, aovs=["halves"], **SIZE)
    h = halves(r.aovs)
    with pytest.raises(ValueError, match="albedo: expected shape"):
        penumbra.denoise(**{**h, "albedo": h["albedo"][:, :10]})
    bad = h["depth"].copy()
    bad[1, 3, 4] = -np.inf
    with pytest.raises(ValueError, match="depth: non-finite value"):
        penumbra.denoise(**{**h, "depth": bad})
    nan = h["color"].copy()
    nan[0, 0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="color: non-finite"):
        penumbra.denoise(**{**h, "color": nan})
    with pytest.raises(ValueError, match="method must be 'nfor' or 'cross_bilateral'"):
        penumbra.denoise(**h, method="oidn")
    with pytest.raises(ValueError, match="denoise needs spp >= 2"):
        default_scene.render(integrator="path", spp=1, denoise=True, **SIZE)
    with pytest.raises(ValueError, match="denoise needs integrator 'path'"):
        default_scene.render(denoise=True, **SIZE)
    with pytest.raises(ValueError, match="halves"):
        default_scene.render(aovs=["halves"], **SIZE)
