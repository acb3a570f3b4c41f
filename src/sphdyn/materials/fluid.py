r"""What the fluid models share: an energy equation solved exactly for an
equation of state linear in the internal energy (their stress is isotropic,
``-p I``: :func:`~sphdyn.materials.base.isotropic6`).

For a fluid :math:`\sigma = -pI`, so the energy equation of the common
kernel (``dt/2 (sigma_old + sigma_new):D / rho``, as for the solids) reads

.. math:: e^{n+1} = e^n + \Delta q - \frac{\Delta t\,\mathrm{tr}D}{2\rho}
          \,(p^n + p^{n+1}),

with :math:`\Delta q` a source (an explosive's released chemical energy).
With :math:`p^{n+1} = a + b\,e^{n+1}` (both equations of state of
:mod:`sphdyn.materials.eos` are linear in ``e`` at fixed density) this is
linear in :math:`e^{n+1}`:

.. math:: e^{n+1} = \frac{e^n + \Delta q - k\,(p^n + a)}{1 + k\,b}, \qquad
          k = \frac{\Delta t\,\mathrm{tr}D}{2\rho}

(Wilkins 1964, the energy-pressure iteration of HEMP solved in closed form).
A pressure below the cutoff :math:`p_{min} \le 0` is raised to it and the
energy recomputed with it, so the work always pairs with the force pass.

The model and its tests: docs/theory.md, "Materials".
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy")
def fluid_energy(e_old, dq, p_old, a, b, p_min, tr_d, dt, rho):
    """One step of the fluid energy equation (module docstring).

    Parameters
    ----------
    e_old : float, specific internal energy at the start of the step [J/kg].
    dq : float, energy added by a source in the step [J/kg].
    p_old : float, pressure at the start of the step [Pa].
    a, b : float, the new pressure is ``a + b e`` [Pa], [Pa kg/J].
    p_min : float, pressure cutoff [Pa] (<= 0).
    tr_d : float, trace of the rate of deformation [1/s].
    dt : float, time step [s].
    rho : float, density at the end of the step [kg/m^3].

    Returns
    -------
    (e_new [J/kg], p_new [Pa])
    """
    k = 0.5 * dt * tr_d / rho
    e_new = (e_old + dq - k * (p_old + a)) / (1.0 + k * b)
    p_new = a + b * e_new
    if p_new < p_min:
        p_new = p_min
        e_new = e_old + dq - k * (p_old + p_new)
    return e_new, p_new
