"""The two-layer system in two dimensions: where it loses hyperbolicity and which
restoration covers every direction (the derivation is in docs/two_d.md).

The 2D pseudo-Jacobian in a direction n is built here from the fluxes of the 2D system,
independently of pdeflow's 1D code, and compared with it: its spectrum is the 1D
quartic's at the normal velocities plus the two contact waves u_k . n, so the 2D system is
hyperbolic in direction n exactly when |du . n| is outside the 1D band (F_c1, F_c2), and
hyperbolic in every direction exactly when |du| <= F_c1.
"""

from __future__ import annotations

import numpy as np
import pytest

from pdeflow.models.two_layer.hyperbolicity import band_edges, discriminant, eigenvalues

G = 9.81
DIRECTIONS = 64


def directions(count: int = DIRECTIONS) -> np.ndarray:
    """``count`` unit normals n = (cos a, sin a), a over the half circle (n and -n give
    the same spectrum up to sign)."""
    a = np.pi * np.arange(count) / count
    return np.stack([np.cos(a), np.sin(a)], axis=1)


def jacobian_2d(h1: float, u1: np.ndarray, h2: float, u2: np.ndarray, n: np.ndarray,
                r: float, g: float = G) -> np.ndarray:
    """A_n = n_x A_x + n_y A_y of the 2D two-layer system in the variables
    (h1, h1 u1, h1 v1, h2, h2 u2, h2 v2): the Jacobian of each layer's flux
    (h w, h u w + g h^2/2 n_x, h v w + g h^2/2 n_y), w = u . n, plus the coupling
    g h1 n d_n h2 (layer 1's momenta) and r g h2 n d_n h1 (layer 2's)."""
    A = np.zeros((6, 6))
    nx, ny = n
    for k, (h, (u, v)) in enumerate(((h1, u1), (h2, u2))):
        w = u * nx + v * ny
        b = 3 * k
        A[b, b:b + 3] = (0.0, nx, ny)
        A[b + 1, b:b + 3] = (-u * w + g * h * nx, w + u * nx, u * ny)
        A[b + 2, b:b + 3] = (-v * w + g * h * ny, v * nx, w + v * ny)
    A[1, 3] += g * h1 * nx
    A[2, 3] += g * h1 * ny
    A[4, 0] += r * g * h2 * nx
    A[5, 0] += r * g * h2 * ny
    return A


State = tuple[float, np.ndarray, float, np.ndarray, float]


def random_states(count: int, seed: int) -> list[State]:
    """(h1 [m], u1 [m/s], h2 [m], u2 [m/s], r): depths over two decades, density ratios
    in (0.05, 0.95), velocities up to a few sqrt(g H) in any direction."""
    rng = np.random.default_rng(seed)
    states = []
    for _ in range(count):
        h1, h2 = 10.0 ** rng.uniform(-2, 0, size=2)
        scale = np.sqrt(G * (h1 + h2))
        u1, u2 = rng.normal(0.0, 1.5 * scale, size=(2, 2))
        states.append((h1, u1, h2, u2, rng.uniform(0.05, 0.95)))
    return states


def banded_states(count: int, seed: int):
    """:func:`random_states` that have a non-hyperbolic band, each with its edges
    (F_c1, F_c2) [m/s] appended."""
    for h1, u1, h2, u2, r in random_states(count, seed):
        edges = band_edges(h1, h2, G, r)
        if edges is not None:
            yield h1, u1, h2, u2, r, *edges


def hyperbolic_in(h1: float, u1: np.ndarray, h2: float, u2: np.ndarray, r: float,
                  n: np.ndarray) -> bool:
    """The 1D system along n (normal velocities) has four real roots: pdeflow's
    discriminant (a closed form, no eigenvalue solver) is >= 0."""
    return discriminant(h1, h2, float(u1 @ n), float(u2 @ n), G, r) >= 0.0


@pytest.mark.parametrize("seed", [1, 2])
def test_2d_spectrum_is_the_1d_quartic_plus_contact_waves(seed):
    """For random states and 64 directions, the eigenvalues of the 2D A_n are the four
    roots of the 1D characteristic polynomial at (u1 . n, u2 . n) and the contact
    speeds u1 . n, u2 . n. Tolerance 1e-6 sqrt(g H): a general eigenvalue solver on a
    6x6 matrix of entries ~ g H loses ~ sqrt(eps) near double roots."""
    for h1, u1, h2, u2, r in random_states(40, seed):
        scale = np.sqrt(G * (h1 + h2))
        for n in directions():
            got = np.linalg.eigvals(jacobian_2d(h1, u1, h2, u2, n, r))
            want = np.concatenate([eigenvalues(h1, h2, float(u1 @ n), float(u2 @ n), G, r),
                                   [u1 @ n, u2 @ n]])
            for lam in want:  # each expected root matched by the nearest computed one
                assert np.min(np.abs(got - lam)) < 1e-6 * scale, (h1, h2, u1, u2, r, n)


def test_hyperbolic_in_a_direction_iff_the_normal_shear_is_outside_the_band():
    """Whether direction n is hyperbolic depends on |du . n| alone: inside the 1D band
    (F_c1, F_c2) the quartic has a complex pair, outside it has not."""
    checked = 0
    for h1, u1, h2, u2, r, lo, hi in banded_states(200, 3):
        for n in directions():
            dun = abs(float((u1 - u2) @ n))
            if min(abs(dun - lo), abs(dun - hi)) < 1e-6 * lo:
                continue  # at an edge to round-off: either answer is right
            assert hyperbolic_in(h1, u1, h2, u2, r, n) == (not lo < dun < hi)
            checked += 1
    assert checked > 5000


def restored(h1: float, u1: np.ndarray, h2: float, u2: np.ndarray, r: float,
             target: float) -> tuple[np.ndarray, np.ndarray]:
    """The exchange of docs/two_d.md: momentum moved between the layers along du, total
    momentum rho1 h1 u1 + rho2 h2 u2 kept, until |du| = ``target``."""
    du = u1 - u2
    mean = (r * h1 * u1 + h2 * u2) / (r * h1 + h2)  # per rho2: the momentum's velocity
    du_new = du * (target / np.linalg.norm(du))
    # u1 = mean + w2 du, u2 = mean - w1 du with the mass weights w1 + w2 = 1
    w1 = r * h1 / (r * h1 + h2)
    return mean + (1.0 - w1) * du_new, mean - w1 * du_new


def test_restoring_along_du_to_the_lower_band_edge_makes_every_direction_hyperbolic():
    """Every random state whose |du| exceeds F_c1, restored along du to |du| = F_c1 (a
    hair below: the kernels aim at the edge from the hyperbolic side), is hyperbolic in
    all 64 directions, and its total momentum is unchanged."""
    restored_count = 0
    for h1, u1, h2, u2, r, lo, _ in banded_states(300, 4):
        if np.linalg.norm(u1 - u2) <= lo:
            continue
        v1, v2 = restored(h1, u1, h2, u2, r, lo * (1.0 - 1e-9))
        np.testing.assert_allclose(r * h1 * v1 + h2 * v2, r * h1 * u1 + h2 * u2,
                                   rtol=1e-12, atol=1e-12 * np.sqrt(G * (h1 + h2)) * (h1 + h2))
        (a, b), (c, d) = v1 - v2, u1 - u2
        assert abs(a * d - b * c) <= 1e-9 * np.linalg.norm(u1 - u2) ** 2  # along du
        assert all(hyperbolic_in(h1, v1, h2, v2, r, n) for n in directions())
        restored_count += 1
    assert restored_count > 100


def test_a_state_above_the_band_is_hyperbolic_along_du_but_not_in_every_direction():
    """Unlike 1D, |du| >= F_c2 is not safe in 2D: the directions where |du . n| falls
    inside the band are not hyperbolic. So the 2D restoration must bring every |du| >
    F_c1 down to F_c1, not only those inside the band."""
    found = 0
    for h1, u1, h2, u2, r, _, hi in banded_states(300, 5):
        du = u1 - u2
        if np.linalg.norm(du) <= hi * (1.0 + 1e-6):
            continue
        along = du / np.linalg.norm(du)
        assert hyperbolic_in(h1, u1, h2, u2, r, along)
        assert not all(hyperbolic_in(h1, u1, h2, u2, r, n) for n in directions(256))
        found += 1
    assert found > 20
