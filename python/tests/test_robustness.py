"""Inputs that could reach the extension in unsafe shapes: memory shared between an input and
`out` through different NumPy objects, misaligned buffers, read-only caches made writeable,
sizes that overflow, rotations in every accepted form."""

import numpy as np
import pytest

import so3fft

B = 4
N = 2 * B


def _aliased_pair(n_in, n_out, dtype_in, dtype_out):
    """Two arrays that are different NumPy objects over one buffer (NumPy's base objects
    differ, so rust-numpy's borrow tracking cannot see the overlap)."""
    buf = bytearray(max(n_in * np.dtype(dtype_in).itemsize, n_out * np.dtype(dtype_out).itemsize))
    a = np.frombuffer(buf, dtype_in, count=n_in)
    b = np.frombuffer(buf, dtype_out, count=n_out)
    return a, b


def test_out_sharing_memory_with_the_input_through_another_object():
    plan = so3fft.Plan(B)
    rng = np.random.default_rng(1)
    coeffs = rng.standard_normal(plan.num_coeffs) + 1j * rng.standard_normal(plan.num_coeffs)
    samples = plan.inverse(coeffs)
    want = plan.forward(samples)
    x, out = _aliased_pair(samples.size, plan.num_coeffs, complex, complex)
    x = x.reshape(samples.shape)
    x[...] = samples  # frombuffer of a bytearray is writeable
    got = plan.forward(x, out=out)
    assert got is out
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_misaligned_arrays_are_copied_or_rejected():
    plan = so3fft.Plan(B)
    n = plan.num_coeffs
    raw = np.zeros(n * 16 + 8, np.uint8)
    mis = raw[1 : 1 + n * 16].view(complex)  # contiguous but not 8-byte aligned
    assert not mis.flags.aligned
    mis[...] = 0
    mis[so3fft.coef_index(B, 2, 1, -1)] = 1.0
    samples = plan.inverse(mis)  # the input is copied to an aligned array
    back = plan.forward(samples)
    np.testing.assert_allclose(back, np.asarray(mis), atol=1e-13)
    with pytest.raises(ValueError, match="aligned"):
        plan.forward(samples, out=mis)


def test_changing_a_returned_index_table_changes_nothing_else():
    a = so3fft.coef_degrees_orders(B)
    a[:] = 0
    fhat = np.arange(so3fft.num_coeffs(B), dtype=complex)
    dense = so3fft.to_dense(fhat)
    for k, (l, m, mp) in enumerate(so3fft.coef_degrees_orders(B)):
        assert so3fft.coef_index(B, int(l), int(m), int(mp)) == k
        assert dense[l, m + B - 1, mp + B - 1] == k
    s = so3fft.s2_coef_degrees_orders(B)
    s[:] = 0
    assert (so3fft.s2_coef_degrees_orders(B)[1:, 0] > 0).any()


def test_to_dense_checks_the_size_before_building_tables():
    with pytest.raises(ValueError, match="coefficients"):
        so3fft.to_dense(np.zeros(10), B=2048)


def test_rotate_s2_coeffs_caps_the_bandwidth():
    with pytest.raises(ValueError, match="invalid bandwidth"):
        so3fft._so3fft.rotate_s2_coeffs(2**32, np.zeros(0, complex), (0.0, 0.0, 0.0))


def test_many_fields_that_overflow_are_an_error():
    plan = so3fft._so3fft.S2Plan(B, 1, "estimate")
    empty = np.zeros(0, complex)
    with pytest.raises(ValueError, match="too many"):
        plan.forward(empty, np.zeros(0, complex), 2**62, True)


def test_top_peaks_of_a_grid_with_nan():
    grid = np.ones((N, N, N))
    grid[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        so3fft.top_peaks(grid)


@pytest.mark.parametrize(
    "starts",
    [
        (0.3, 1.0, 2.0),
        [0.3, 1.0, 2.0],
        so3fft.Rotation(0.3, 1.0, 2.0),
        [so3fft.Rotation(0.3, 1.0, 2.0)],
        [(0.3, 1.0, 2.0)],
        np.array([[0.3, 1.0, 2.0]]),
    ],
)
def test_refine_takes_one_rotation_in_every_form(starts):
    # The maximum of |D^1_{00}|^2 = cos^2(beta) (times a constant) near beta = 1 is beta = 0
    # or pi; starting at beta = 1 the search climbs to one of them.
    c = np.zeros(so3fft.num_coeffs(B), complex)
    c[so3fft.coef_index(B, 1, 0, 0)] = 1.0
    (g, value), = so3fft.refine(c, starts)
    assert min(g.beta, np.pi - g.beta) < 1e-7


def test_refine_of_no_rotations_and_complex_angles():
    c = np.zeros(so3fft.num_coeffs(B), complex)
    assert so3fft.refine(c, []) == []
    with pytest.raises(TypeError):
        so3fft.refine(c, [(0.1j, 0.0, 0.0)])


def test_match_reports_each_maximum_once():
    # A pattern and signal with one dominant correlation peak: several grid peaks refine to
    # the same rotation, which is reported once.
    s2 = so3fft.S2Plan(B, real=True)
    rng = np.random.default_rng(3)
    f = s2.inverse(_real_coeffs(rng, B))
    found = so3fft.Correlation(B, real=True).match(f, f, k=10, min_angle=0.0)
    # A function correlated with itself is best at the identity (|C| is largest where the
    # pattern lies on the signal), so the best rotation found is the identity.
    assert found and found[0][0].angle_to(so3fft.Rotation(0.0, 0.0, 0.0)) < 1e-6
    angles = [g for g, _ in found]
    for i, g in enumerate(angles):
        for h in angles[:i]:
            assert g.angle_to(h) > 1e-6


def _real_coeffs(rng, B):
    """Coefficients of a real function: fhat(l, -m) = (-1)^m conj(fhat(l, m))."""
    c = np.zeros(B * B, complex)
    for l in range(B):
        for m in range(0, l + 1):
            z = rng.standard_normal() + (1j * rng.standard_normal() if m else 0)
            c[so3fft.s2_coef_index(B, l, m)] = z
            if m:
                c[so3fft.s2_coef_index(B, l, -m)] = (-1) ** m * np.conj(z)
    return c
