"""The undamped modes of a structure: K φ = ω² M φ with K and M positive definite (Chopra,
Dynamics of Structures, §10.2), solved on M^-1/2 K M^-1/2 (M diagonal) or L^-1 K L^-T
(M = L Lᵀ dense). Shared by the planar frames (frame2d) and the buildings (building3d)."""

import numpy as np


def _symmetric_form(K, M):
    """(A, back): the symmetric operator A whose eigenvalues are the ω², and back(y) the mode
    shapes Φ of its eigenvectors y (Φᵀ M Φ = I); M dense or its diagonal."""
    M = np.asarray(M, float)
    with np.errstate(all="ignore"):
        if M.ndim == 1:
            s = 1 / np.sqrt(M)
            A, back = s[:, None] * K * s[None, :], lambda y: s[:, None] * y
        else:
            Li = np.linalg.inv(np.linalg.cholesky(M))
            A, back = Li @ K @ Li.T, lambda y: Li.T @ y
    if not np.all(np.isfinite(A)):
        raise np.linalg.LinAlgError("K M^-1 leaves the doubles")
    return A, back


def _omega(lam):
    """ω of the computed ω²: K and M are positive definite (the callers factor both first),
    so every ω² is positive in exact arithmetic; one computed <= 0, inf or NaN (masses and
    stiffness too disparate for double precision, e.g. a floor of 1e-12 kg among floors of
    1e5 kg) raises LinAlgError rather than being clipped to a zero frequency."""
    if not (np.all(np.isfinite(lam)) and lam[0] > 0):
        raise np.linalg.LinAlgError(f"a computed squared frequency is {lam[0]!r}")
    return np.sqrt(lam)


def modes(K, M):
    """(ω ascending, Φ) of K φ = ω² M φ, Φᵀ M Φ = I (see _omega for what is refused)."""
    A, back = _symmetric_form(K, M)
    lam, y = np.linalg.eigh(A)
    return _omega(lam), back(y)


def frequencies(K, M):
    """ω ascending of K φ = ω² M φ alone: LAPACK's eigenvalues without vectors (eigvalsh),
    which differ from eigh's in the last bits — the frames' Rayleigh coefficients, and so
    the physics digest of their stored references (martello.reference.store), are made
    from these."""
    A, _ = _symmetric_form(K, M)
    return _omega(np.linalg.eigvalsh(A))
