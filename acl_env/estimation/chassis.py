"""Virtual chassis (paper section 2.3; Rollinson & Choset 2011) and the pole axis, pure numpy.

The virtual chassis is a body frame for a snake of changing shape: origin at the mean of the
module positions, axes along the principal axes of the centred positions (the columns of V in
``U S V^T = P``, the paper's two unnumbered equations after Eq. 5).

**The pole case.** For a short snake wrapped on a pole the principal axes are nearly degenerate:
the paper's 20-module snake makes about 2.3 turns, whose variance along the pole (``L^2 / 12``
for an axial extent ``L`` ~ 0.23 m) is about that across it (``r^2 / 2`` for a radius ``r`` ~
0.09 m). Which principal axis is the pole axis then changes from shape to shape, and the first
one is often across the pole. :func:`helix_axis` therefore finds the pole (helix) axis from the
shape itself, by a least-squares cylinder fit, and :func:`pole_axis_column` says which chassis
column it is closest to.
"""

from __future__ import annotations

import numpy as np


def _head_weights(n: int) -> np.ndarray:
    """Weights that are positive at the head (index 0) and negative at the tail, summing to 0."""
    return 0.5 * (n - 1) - np.arange(n)


def _as_points(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < 3:
        raise ValueError(f"points must have shape (n >= 3, 3), got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise ValueError("points must be finite")
    return points


def virtual_chassis(
    points: np.ndarray, previous: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The virtual chassis of a snake shape: ``(origin, axes)``.

    Args:
        points: module (or joint) positions, shape ``(n, 3)``, head first.
        previous: the ``axes`` of the previous frame, to keep the signs consistent over time.

    Returns:
        ``origin`` (3,), the mean of ``points``; ``axes`` (3, 3), a rotation whose columns are
        the chassis x, y, z: the principal axes of the centred points in decreasing order of
        spread (SVD). x points toward the head (the x coordinate decreases, in the least-squares
        sense, from head to tail); y is sign-consistent with ``previous`` (without one, its
        sign makes the third moment of the y coordinates positive); z = x cross y.

    In the pole case the first column need not be the pole axis (module docstring): use
    :func:`helix_axis` and :func:`pole_axis_column`.
    """
    points = _as_points(points)
    origin = points.mean(axis=0)
    centred = points - origin
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    x, y = vt[0].copy(), vt[1].copy()
    if (centred @ x) @ _head_weights(len(points)) < 0.0:
        x = -x
    if previous is not None:
        previous = np.asarray(previous, dtype=float)
        if previous.shape != (3, 3):
            raise ValueError(f"previous must be a (3, 3) rotation, got shape {previous.shape}")
        flip = y @ previous[:, 1] < 0.0
    else:
        flip = np.sum((centred @ y) ** 3) < 0.0
    if flip:
        y = -y
    return origin, np.column_stack([x, y, np.cross(x, y)])


def to_chassis(points: np.ndarray, origin: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """Coordinates of ``points`` (n, 3) in the chassis frame ``(origin, axes)``."""
    return (np.asarray(points, dtype=float) - origin) @ axes


def winding_axis(points: np.ndarray) -> np.ndarray:
    """Unit vector area of the centred polyline: the axis a coiled body winds around.

    The sum of ``(p_i - o) x (p_i+1 - p_i)`` is twice the area the curve sweeps about its mean;
    for a helix of a few turns it is dominated by the turns, so it points along the helix axis
    (right-handed about the head-to-tail sense of winding). A rough start for :func:`helix_axis`.
    """
    points = _as_points(points)
    centred = points - points.mean(axis=0)
    area = np.sum(np.cross(centred[:-1], centred[1:]), axis=0)
    norm = np.linalg.norm(area)
    if norm < 1e-12:
        raise ValueError("the points do not wind around any axis (zero vector area)")
    return area / norm


def _plane_basis(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors completing ``direction`` to an orthonormal basis."""
    helper = np.eye(3)[np.argmin(np.abs(direction))]
    u = np.cross(direction, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(direction, u)


def _circle_fit(points: np.ndarray, direction: np.ndarray) -> tuple[np.ndarray, float]:
    """Algebraic (Kasa) circle fit of the points projected along ``direction``: centre, radius."""
    origin = points.mean(axis=0)
    u, v = _plane_basis(direction)
    a, b = (points - origin) @ u, (points - origin) @ v
    design = np.column_stack([2.0 * a, 2.0 * b, np.ones_like(a)])
    (ca, cb, c0), *_ = np.linalg.lstsq(design, a**2 + b**2, rcond=None)
    return origin + ca * u + cb * v, float(np.sqrt(max(c0 + ca**2 + cb**2, 0.0)))


def helix_axis(
    points: np.ndarray, direction: np.ndarray | None = None, iterations: int = 50
) -> tuple[np.ndarray, np.ndarray, float]:
    """The pole (helix) centre line of a coiled shape, by a least-squares cylinder fit.

    Minimises ``sum_i (dist(p_i, axis) - R)^2`` over the axis line and ``R`` (Levenberg-Marquardt,
    analytic Jacobian), starting from ``direction`` or the :func:`winding_axis` and a circle fit.

    Returns ``(point, direction, radius)``: ``point`` on the axis (the foot of the perpendicular
    from the mean of ``points``), the unit ``direction`` oriented from head to tail (the axial
    coordinate grows, in the least-squares sense, toward the tail: the climbing direction of
    a snake whose head is its lowest end) and the fitted radius (m).
    """
    points = _as_points(points)
    d = winding_axis(points) if direction is None else np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    centre, radius = _circle_fit(points, d)

    def residuals(d: np.ndarray, c: np.ndarray, r: float) -> tuple[np.ndarray, ...]:
        w = points - c
        along = w @ d
        perp = w - along[:, None] * d
        dist = np.linalg.norm(perp, axis=1)
        return dist - r, along, perp / np.maximum(dist, 1e-12)[:, None]

    res, along, normal = residuals(d, centre, radius)
    cost, damping = float(res @ res), 1e-3
    for _ in range(iterations):
        u, v = _plane_basis(d)
        nu, nv = normal @ u, normal @ v
        # Parameters: tilt of d toward u, v; shift of the centre along u, v; radius.
        jac = np.column_stack([-along * nu, -along * nv, -nu, -nv, -np.ones_like(nu)])
        jtj, jtr = jac.T @ jac, jac.T @ res
        while damping < 1e8:
            step = np.linalg.solve(jtj + damping * np.diag(np.diag(jtj) + 1e-15), -jtr)
            d_new = d + step[0] * u + step[1] * v
            d_new /= np.linalg.norm(d_new)
            c_new, r_new = centre + step[2] * u + step[3] * v, radius + step[4]
            res_new, along_new, normal_new = residuals(d_new, c_new, r_new)
            if res_new @ res_new <= cost:
                d, centre, radius = d_new, c_new, r_new
                res, along, normal = res_new, along_new, normal_new
                converged = cost - res_new @ res_new <= 1e-14 * max(cost, 1e-30)
                cost, damping = float(res_new @ res_new), max(damping / 10.0, 1e-12)
                break
            damping *= 10.0
        else:
            break
        if converged:
            break
    if (points @ d) @ _head_weights(len(points)) > 0.0:
        d = -d
    foot = centre + ((points.mean(axis=0) - centre) @ d) * d
    return foot, d, float(radius)


def pole_axis_column(axes: np.ndarray, direction: np.ndarray) -> int:
    """Which chassis column (0 = x, 1 = y, 2 = z) is closest to the pole ``direction``."""
    return int(np.argmax(np.abs(np.asarray(axes, dtype=float).T @ direction)))


def distance_to_axis(points: np.ndarray, point: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Euclidean distance of each point (n, 3) to the line through ``point`` along ``direction``."""
    w = np.asarray(points, dtype=float) - point
    return np.linalg.norm(w - np.outer(w @ direction, direction), axis=1)
