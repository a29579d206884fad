"""A point target's axial and lateral widths within 20 % of SIMUS's, for the same probe."""

from ground_truth.psf_reference import model_psf, PROBES, simus_psf
import pytest

DEPTH = 0.02  # m
F_NUMBER = 1.5
CYCLES = 2.0


@pytest.mark.parametrize('probe', PROBES)
def test_the_point_spread_matches_simus(tmp_path, probe):
    reference = simus_psf(probe, cycles=CYCLES, f_number=F_NUMBER, depth=DEPTH)
    model = model_psf(tmp_path, centre_frequency=reference['fc'],
                      bandwidth=reference['bandwidth'], aperture=reference['aperture'],
                      cycles=CYCLES, f_number=F_NUMBER, depth=DEPTH)
    for axis in ('axial', 'lateral'):
        print(f'{probe} {axis}: model {model[axis] * 1e3:.3f} mm, SIMUS '
              f'{reference[axis] * 1e3:.3f} mm ({model[axis] / reference[axis] - 1:+.1%})')
    assert model['axial'] == pytest.approx(reference['axial'], rel=0.2)
    assert model['lateral'] == pytest.approx(reference['lateral'], rel=0.2)
