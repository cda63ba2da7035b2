"""Object position covariance from robot position covariance, to first order, through an
equilibrium's sensitivities (issue 28 part 2; derivation in docs/sheet_sensitivity.md,
the derivatives in :mod:`taut.sheet.fk._sensitivity`)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_array, require_instance
from ..errors import InvalidInputError
from .fk.results import Equilibrium

__all__ = ["object_covariance"]


def object_covariance(equilibrium: Equilibrium, robot_covariance: ArrayLike
                      ) -> np.ndarray:
    """Covariance of the object position from the robots' position covariance, to first
    order: :math:`\\Sigma_o = J \\Sigma_r J^T` with ``J = equilibrium.jacobian`` reshaped
    to (3, 2N) (valid while the taut set holds: errors well inside
    ``equilibrium.taut_margin``; docs/sheet_sensitivity.md).

    Parameters
    ----------
    equilibrium : Equilibrium
        A state from forward kinematics.
    robot_covariance : float or array_like, shape (N, 2, 2) or (2N, 2N)
        A variance per axis (length unit squared; every robot independent, isotropic),
        one 2x2 covariance per robot, or the full covariance of the stacked
        (x_1, y_1, x_2, ...) robot positions.

    Returns
    -------
    ndarray, shape (3, 3)
        Covariance of (x_o, y_o, z_o), length unit squared.

    Examples
    --------
    >>> import numpy as np
    >>> import taut.sheet as ts
    >>> team = ts.SheetTeam(ts.Sheet([[0, 0], [1, 0], [0, 1]]), 1.0)
    >>> e = ts.forward_kinematics(team, [[0, 0], [0.9, 0], [0, 0.9]]).lowest
    >>> cov = ts.object_covariance(e, 1e-6)             # 1 mm on a 1 m sheet, per axis
    >>> cov.shape, bool(np.all(np.linalg.eigvalsh(cov) >= -1e-18))
    ((3, 3), True)
    """
    J = require_instance(equilibrium, Equilibrium, "equilibrium").jacobian
    n2 = J.shape[1] * 2
    C = as_array(robot_covariance, "robot_covariance")
    if C.ndim == 0:
        if C < 0:
            raise InvalidInputError("robot_covariance", "a variance must be >= 0")
        S = float(C) * np.eye(n2)
    elif C.shape == (n2 // 2, 2, 2):
        S = np.zeros((n2, n2))
        for i in range(n2 // 2):
            S[2 * i:2 * i + 2, 2 * i:2 * i + 2] = C[i]
    elif C.shape == (n2, n2):
        S = C
    else:
        raise InvalidInputError("robot_covariance", f"must be a variance, shape "
                                f"({n2 // 2}, 2, 2) or ({n2}, {n2}); got {C.shape}")
    Jf = J.reshape(3, n2)
    return Jf @ S @ Jf.T
