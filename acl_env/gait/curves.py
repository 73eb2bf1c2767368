"""Backbone curves of the paper (Eq. 1-2) and their curvature integration (Eq. 3-5), pure numpy.

The curve parameter ``t`` is the angle around the pole (axis = z); the gait phase enters as
``w h = 2 pi phase``. Curvature ``kappa`` and torsion ``tau`` come from the analytic derivatives
of the curve, arc length ``s`` from a cumulative third-order (three-point) rule on a grid of ``t``.
Everything is vectorised over a batch of phases, so a whole gait cycle costs one pass.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PitchVaryingHelix:
    """The pitch-varying helix of Eq. 1 (Eq. 2 when ``amp_radial = 0``), lengths in metres.

    x = cos t (r + A_r cos(k_r t + w h)),  y = sin t (r + A_r cos(k_r t + w h)),
    z = p t + A_p sin(Omega t + w h),      p = pitch / (2 pi).
    """

    radius: float
    pitch: float
    amp_pitch: float = 0.0
    spatial_freq: float = 2.0
    amp_radial: float = 0.0
    radial_freq: float = 2.0

    def derivatives(self, t: np.ndarray, phase: np.ndarray) -> tuple[np.ndarray, ...]:
        """Curve and its first three derivatives in ``t``, each ``(*phase.shape, *t.shape, 3)``."""
        wh = 2.0 * np.pi * np.asarray(phase, dtype=float)[..., None]
        p = self.pitch / (2.0 * np.pi)
        arg_r = self.radial_freq * t + wh
        k, a = self.radial_freq, self.amp_radial
        rho = [
            self.radius + a * np.cos(arg_r),
            -a * k * np.sin(arg_r),
            -a * k**2 * np.cos(arg_r),
            a * k**3 * np.sin(arg_r),
        ]
        c, s = np.cos(t), np.sin(t)
        # Leibniz rule for rho(t) * (cos t, sin t): d^n/dt^n of cos t is cos(t + n pi / 2).
        trig = [(c, s), (-s, c), (-c, -s), (s, -c)]
        binom = [[1], [1, 1], [1, 2, 1], [1, 3, 3, 1]]
        arg_z = self.spatial_freq * t + wh
        om, ap = self.spatial_freq, self.amp_pitch
        z = [
            p * t + ap * np.sin(arg_z),
            p + ap * om * np.cos(arg_z),
            -ap * om**2 * np.sin(arg_z),
            -ap * om**3 * np.cos(arg_z),
        ]
        out = []
        for n in range(4):
            x = sum(binom[n][m] * rho[n - m] * trig[m][0] for m in range(n + 1))
            y = sum(binom[n][m] * rho[n - m] * trig[m][1] for m in range(n + 1))
            out.append(np.stack(np.broadcast_arrays(x, y, z[n]), axis=-1))
        return tuple(out)


@dataclass(frozen=True)
class CurveSamples:
    """A curve sampled on a fine grid of ``t`` for a batch of phases (leading axis)."""

    t: np.ndarray  # (M,)
    points: np.ndarray  # (K, M, 3)
    tangent: np.ndarray  # (K, M, 3)
    normal: np.ndarray  # (K, M, 3)
    s: np.ndarray  # (K, M) arc length from t = 0
    kappa: np.ndarray  # (K, M)
    tau: np.ndarray  # (K, M)
    twist: np.ndarray  # (K, M) cumulative int_0^s tau ds (quadrature, or summed turns)
    speed: np.ndarray  # (K, M) ds/dt
    dt: float  # grid step of t
    turns: np.ndarray  # (K, M - 1) the Frenet normal's turn over each interval (normal_turns)


def _increments(y: np.ndarray, dt: float) -> np.ndarray:
    """Integral of ``y`` over each interval of a uniform grid of step ``dt`` (last axis).

    Each interval uses the three-point rule h/12 (5 y_i + 8 y_i+1 - y_i+2) (the last one its
    mirror), third-order accurate: a coarse grid then meets 1e-4 rad on the joint angles.
    """
    inc = np.empty((*y.shape[:-1], y.shape[-1] - 1))
    inc[..., :-1] = 5.0 * y[..., :-2] + 8.0 * y[..., 1:-1] - y[..., 2:]
    inc[..., -1] = -y[..., -3] + 8.0 * y[..., -2] + 5.0 * y[..., -1]
    inc *= dt / 12.0
    return inc


def _cumsum0(inc: np.ndarray) -> np.ndarray:
    """Running sum of interval increments along the last axis, starting at 0."""
    return np.concatenate([np.zeros((*inc.shape[:-1], 1)), np.cumsum(inc, axis=-1)], axis=-1)


def _cumint(y: np.ndarray, dt: float) -> np.ndarray:
    """Cumulative integral along the last axis on a uniform grid of step ``dt``, starting at 0
    (the three-point rule of :func:`_increments`)."""
    return _cumsum0(_increments(y, dt))


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot product over the last axis (length 3); the same sum as ``np.sum(a * b, axis=-1)``,
    written out because numpy's reduction over a length-3 axis is several times slower."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product over the last axis; ``np.cross``'s arithmetic without its overhead."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0), axis=-1)


# rad: the largest gap, over one grid interval, between the quadrature of tau and the Frenet
# normal's measured turn that still counts as agreement (twist_mismatch).
TWIST_MISMATCH = 0.05


def normal_turns(
    tangent: np.ndarray, normal: np.ndarray, kappa2_tau: np.ndarray, s: np.ndarray
) -> np.ndarray:
    """How far the Frenet normal turns about the tangent over each grid interval (rad).

    The normal at one sample is carried to the next by the smallest rotation between the two
    tangents, and the angle from it to the next normal is measured. Adding the area between the
    tangent's path on the unit sphere and that shortest path, ``-h^3 kappa^2 tau / 12``, makes
    it the parallel transport to third order (the measured angle alone is second order). Unlike
    the quadrature of tau it holds where the curve nearly straightens (kappa -> 0): there tau
    spikes too narrowly for any grid while the normal swings through half a turn
    (docs/gait.md#thin-poles). ``kappa2_tau`` is ``kappa^2 tau``, smooth where tau is not.
    """
    a, b = tangent[..., :-1, :], tangent[..., 1:, :]
    n0, n1 = normal[..., :-1, :], normal[..., 1:, :]
    ab = a + b
    dot = _dot(a, b)[..., None]
    moved = n0 - _dot(ab, n0)[..., None] / (1.0 + dot) * ab
    moved += 2.0 * _dot(a, n0)[..., None] * b
    turn = np.arctan2(_dot(_cross(moved, n1), b), _dot(moved, n1))
    h = np.diff(s, axis=-1)
    return turn - h**3 / 24.0 * (kappa2_tau[..., :-1] + kappa2_tau[..., 1:])


def twist_mismatch(samples: CurveSamples) -> float:
    """Largest gap (rad, modulo 2 pi) between the twist and the normal's measured turn over one
    grid interval. On quadrature samples: near 0 where the grid resolves tau, large where not."""
    gap = (np.diff(samples.twist, axis=-1) - samples.turns + np.pi) % (2.0 * np.pi) - np.pi
    return float(np.abs(gap).max())


def transported(samples: CurveSamples) -> CurveSamples:
    """The same samples with the twist summed from the normal's measured turns."""
    return dataclasses.replace(samples, twist=_cumsum0(samples.turns))


def first_rows(samples: CurveSamples, n: int) -> CurveSamples:
    """The samples of the first ``n`` phases only (every per-phase array cut to ``n`` rows)."""
    per_phase = ("points", "tangent", "normal", "s", "kappa", "tau", "twist", "speed", "turns")
    return dataclasses.replace(samples, **{name: getattr(samples, name)[:n] for name in per_phase})


def sample_curve(
    curve: PitchVaryingHelix,
    phases: np.ndarray,
    length: float,
    n_samples: int = 2400,
    transport: bool = False,
) -> CurveSamples:
    """Sample ``curve`` from ``t = 0`` over at least ``length`` metres of arc, for each phase.

    Frenet quantities: kappa = |C' x C''| / |C'|^3, tau = (C' x C'') . C''' / |C' x C''|^2. The
    twist ``int tau ds`` is the quadrature of tau, or with ``transport`` the sum of the normal's
    measured turns (:func:`normal_turns`), for curves whose tau the grid cannot resolve.
    """
    phases = np.atleast_1d(np.asarray(phases, dtype=float))
    # |C'| >= r - A_r around the pole, so this t range always covers `length` of arc.
    t_end = 1.05 * length / max(curve.radius - curve.amp_radial, 1e-9)
    t = np.linspace(0.0, t_end, n_samples)
    c0, c1, c2, c3 = curve.derivatives(t, phases)
    cross = _cross(c1, c2)
    cross_sq = _dot(cross, cross)
    triple = _dot(cross, c3)
    speed = np.sqrt(_dot(c1, c1))
    kappa = np.sqrt(cross_sq) / speed**3
    tau = triple / np.maximum(cross_sq, 1e-300)
    dt = t[1] - t[0]
    s = _cumint(speed, dt)
    tangent = c1 / speed[..., None]
    binormal = cross / np.sqrt(np.maximum(cross_sq, 1e-300))[..., None]
    normal = _cross(binormal, tangent)
    samples = CurveSamples(
        t=t,
        points=c0,
        tangent=tangent,
        normal=normal,
        s=s,
        kappa=kappa,
        tau=tau,
        twist=_cumint(tau * speed, dt),
        speed=speed,
        dt=dt,
        turns=normal_turns(tangent, normal, triple / speed**6, s),
    )
    return transported(samples) if transport else samples


def _interp_rows(x_new: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Row-wise linear interpolation: ``y[k]`` sampled at ``x[k]``, evaluated at ``x_new``."""
    return np.stack([np.interp(x_new, xk, yk) for xk, yk in zip(x, y, strict=True)])


def bellows_integrals(
    samples: CurveSamples, n_joints: int, module_length: float
) -> tuple[np.ndarray, np.ndarray]:
    """The two phase-free integrals of Eq. 4-5 for each joint, shape ``(K, n_joints)`` each.

    ``C_j = int kappa cos(int tau) ds`` and ``S_j = int kappa sin(int tau) ds`` over the two-module
    window ``[j l, (j + 2) l]`` around joint ``j`` (0-based, at ``s = (j + 1) l``), Eq. 3. Rotating
    them by phi_0 gives the joint angles (Eq. 4-5).
    """
    weight = samples.kappa * samples.speed
    cum_c = _cumint(weight * np.cos(samples.twist), samples.dt)
    cum_s = _cumint(weight * np.sin(samples.twist), samples.dt)
    edges = module_length * np.arange(n_joints + 2)
    ce, se = _interp_rows(edges, samples.s, cum_c), _interp_rows(edges, samples.s, cum_s)
    return ce[:, 2:] - ce[:, :-2], se[:, 2:] - se[:, :-2]


def points_at_arclength(samples: CurveSamples, s_query: np.ndarray) -> np.ndarray:
    """Curve points at the given arc lengths, shape ``(K, len(s_query), 3)``."""
    return np.stack(
        [_interp_rows(s_query, samples.s, samples.points[..., d]) for d in range(3)], axis=-1
    )


def surface_frame_offset(samples: CurveSamples, length: float) -> np.ndarray:
    """Mean roll (rad) of a twist-free body frame relative to the pole's outward normal, per phase.

    A bellows chain has no roll joint, so its frame turns relative to the Frenet frame by
    ``-int tau``; the Frenet normal itself sits at an angle ``theta_F`` from the outward radial
    direction. Their sum, averaged over the body, is how much the body is rolled on the pole when
    phi_0 = 0. For a modulated helix it changes with the phase (docs/gait.md#hidden-roll).
    Only the value modulo 2 pi matters to the gait.
    """
    radial = samples.points * np.array([1.0, 1.0, 0.0])
    radial -= _dot(radial, samples.tangent)[..., None] * samples.tangent
    sin = _dot(_cross(radial, samples.normal), samples.tangent)
    cos = _dot(radial, samples.normal)
    # The Frenet angle turns by ~pi where the curve nearly straightens, and so does the twist;
    # their difference is smooth, so it is unwrapped again (a no-op where neither turns fast).
    theta = np.unwrap(np.unwrap(np.arctan2(sin, cos), axis=-1) - samples.twist, axis=-1)
    mean = (
        _interp_rows(np.array([length]), samples.s, _cumint(theta * samples.speed, samples.dt))[
            :, 0
        ]
        / length
    )
    return mean
