"""prizma.spectrum, xyz, lab, delta_e2000, metamer, design_light."""
import numpy as np
import pytest

import prizma


def test_spectrum_table_and_resampling():
    wl, v = prizma.spectrum("F11")
    assert wl.dtype == np.float64 and wl.shape == v.shape and len(wl) > 50
    assert v.max() > 0
    at = np.array([400.0, 550.0, 2000.0])
    wl2, v2 = prizma.spectrum("gaussian:550:20*0.5", at)
    np.testing.assert_array_equal(wl2, at)
    np.testing.assert_allclose(v2, [0.0, 0.5, 0.0], atol=1e-12)
    wl3, v3 = prizma.spectrum("0.25")
    assert wl3[0] == 360 and wl3[-1] == 830 and (v3 == 0.25).all()
    assert "D65" in prizma.named_spectra() and "cc:dark-skin" in prizma.named_spectra()


def test_spectrum_errors():
    with pytest.raises(prizma.InputError, match=r"^spectrum: "):
        prizma.spectrum("no-such-light")
    with pytest.raises(ValueError):  # InputError is a ValueError
        prizma.spectrum(("not", "numbers"))


def test_xyz_of_a_white_under_d65_is_the_d65_white():
    xyz = prizma.xyz("1", illuminant="D65")
    assert xyz[1] == pytest.approx(1.0, abs=1e-6)  # the product is tabulated every 1 nm
    x, y = xyz[0] / xyz.sum(), xyz[1] / xyz.sum()
    assert x == pytest.approx(0.3127, abs=2e-4) and y == pytest.approx(0.3290, abs=2e-4)
    # A pair (wavelengths, values) is the same spectrum as its spec.
    wl, v = prizma.spectrum("cc:red")
    np.testing.assert_allclose(prizma.xyz((wl, v), "D65"), prizma.xyz("cc:red", "D65"), rtol=1e-12)


def test_lab_and_ciede2000():
    np.testing.assert_allclose(prizma.lab([0.95047, 1.0, 1.08883]), [100, 0, 0], atol=0.05)
    # Sharma, Wu, Dalal (2005), table 1, pairs 1 and 7.
    assert prizma.delta_e2000([50, 2.6772, -79.7751], [50, 0, -82.7485]) == pytest.approx(2.0425, abs=1e-4)
    many = prizma.delta_e2000([[50, 2.6772, -79.7751], [50, 0, 0]], [[50, 0, -82.7485], [50, -1, 2]])
    assert many.shape == (2,)
    assert many[0] == pytest.approx(2.0425, abs=1e-4) and many[1] == pytest.approx(2.3669, abs=1e-4)
    with pytest.raises(prizma.InputError):
        prizma.delta_e2000([1, 2], [1, 2])


def test_metamer_matches_under_one_light_and_splits_under_another():
    r = prizma.metamer("cc:4", "D65", "A", bins="linear:400:700:30", basis_size=12)
    wl, v = r["reflectance"]
    assert len(wl) == len(v) and v.min() >= 0 and v.max() <= 1
    assert r["delta_e_match"] < 0.5 and r["delta_e_split"] >= 0.5  # min_split_delta_e


def test_design_light_reveals():
    r = prizma.design_light("cc:4", "cc:7", "reveal", bins="linear:400:700:30")
    assert r["delta_e"] > r["delta_e_reference"]
    wl, v = r["light"]
    assert v.min() >= 0
