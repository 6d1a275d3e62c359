"""The contact's stability bound on the time step: the pieces shared by
meshwear's own bodies (:func:`meshwear.model.stable_time_step`) and the
riders of a mechanism (:meth:`meshwear.mechanism.Mechanism.stable_limit`);
docs/model.md, "Stable time step"."""

import numpy as np

#: fraction of the estimated stability limit accepted as the largest stable dt
STABILITY_MARGIN = 0.9


def vertex_stiffness(body, law):
    """(n,) stiffness (N/m) and damping (N·s/m) of each vertex of ``body``
    against one surface, the larger of the normal and tangential ones."""
    a = body.area_vectors[:, 3]
    c, d, ct, dtan = (law[5 + 2 * j] + law[6 + 2 * j] * a for j in range(4))  # LAW_SLOTS
    return np.maximum(c, ct), np.maximum(d, dtan)


def contact_matrix(weights, r):
    """sum_i w_i J_i^T J_i (6, 6) for J_i = [I, -[r_i]x]."""
    out = np.zeros((6, 6))
    w = weights.sum()
    out[:3, :3] = w * np.eye(3)
    wr = weights @ r
    skew = np.array([[0.0, -wr[2], wr[1]], [wr[2], 0.0, -wr[0]], [-wr[1], wr[0], 0.0]])
    out[:3, 3:] = -skew
    out[3:, :3] = skew
    out[3:, 3:] = np.einsum("i,i", weights, (r * r).sum(1)) * np.eye(3) - np.einsum("i,ij,ik->jk", weights, r, r)
    return out


def stable_step(K, C, M):
    """Smallest per-mode stability limit of the damped oscillator M x'' + C x' + K x = 0."""
    w, U = np.linalg.eigh(M)
    S = U @ np.diag(w ** -0.5) @ U.T
    lam, phi = np.linalg.eigh(S @ K @ S)
    Ct = S @ C @ S
    best = np.inf
    for j in range(len(lam)):
        if lam[j] <= 0.0:
            continue
        omega = np.sqrt(lam[j])
        zeta = phi[:, j] @ Ct @ phi[:, j] / (2.0 * omega)
        best = min(best, 2.0 * (np.sqrt(1.0 + zeta * zeta) - zeta) / omega)
    # a damping-dominated mode: b = c dt / m <= 2
    c_max = np.linalg.eigvalsh(Ct).max()
    if c_max > 0.0:
        best = min(best, 2.0 / c_max)
    return best
