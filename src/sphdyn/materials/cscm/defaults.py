"""Default parameters of the CSCM concrete model (LS-DYNA *MAT_CSCM_CONCRETE).

The "short form" of LS-DYNA material 159 generates every parameter from the
unconfined compression strength f'c and the maximum aggregate size; the
density is always user input. :func:`default_parameters` reproduces that
generation from the fits collected in ``cscm-notes.md`` sec. 2.2 (Murray,
*Users Manual for LS-DYNA Concrete Material Model 159*, FHWA-HRT-05-062,
2007, as transcribed; tags [V]/[S]/[R]/[D] as in the notes) and returns SI
values. Any subset of the full parameter set may be given explicitly and
overrides the generated value. The defaults of f'c and the aggregate size
themselves are those of the deck table
(:class:`~sphdyn.materials.cscm.schema.CscmParams`).

The fits are written in the units they were published in (MPa, mm, psi for
the fluidity fits); the conversion to SI happens here, once, and nothing
outside this module sees MPa.

Parameter names and SI units (the LS-DYNA names, lower case):

=========  ==========  ====================================================
name       unit        meaning
=========  ==========  ====================================================
K, G       Pa          bulk, shear modulus
alpha      Pa          TXC shear surface constant term
theta      -           TXC linear term
lamda      Pa          TXC exponential term
beta       1/Pa        TXC exponent
alpha1     -           TOR/TXC ratio Q1 constant
theta1     1/Pa        Q1 linear term
lamda1     -           Q1 exponential term
beta1      1/Pa        Q1 exponent
alpha2 ..  (as Q1)     TXE/TXC ratio Q2
R          -           cap aspect ratio
X0         Pa          initial cap location (J1, compression positive)
W          -           maximum plastic volume compaction
D1, D2     1/Pa, 1/Pa2 compaction law shape
B, D       -           ductile / brittle softening shape
GFC, GFT,  J/m^2       fracture energies (uniaxial compression, uniaxial
GFS                    tension, pure shear)
pwrc,pwrt  -           shear-to-compression / -tension transition powers
pmod       -           moderate-pressure softening modifier (stored, unused:
                       dmax is a constant, see point.py)
eta0c, nc  s^(1-nc),-  compression fluidity eta_c = eta0c / rate^nc
eta0t, nt  s^(1-nt),-  tension fluidity
overc,     Pa          maximum overstress in compression / tension
overt
srate      -           shear-to-tension fluidity ratio
repow      -           power of the rate enhancement of fracture energy
=========  ==========  ====================================================
"""

from __future__ import annotations

import math

MPA = 1.0e6          # Pa per MPa
PSI_PER_MPA = 145.0377377  # psi per MPa (1 psi = 6894.757 Pa)

#: Poisson ratio of the default moduli.
NU = 0.15
#: Default GFC / GFT (GFS = GFT).
GFC_PER_GFT = 100.0
#: Defaults independent of f'c that the deck reference quotes.
CONSTANT_DEFAULTS = {"B": 100.0, "D": 0.1, "pwrc": 5.0, "pwrt": 1.0,
                     "srate": 1.0, "repow": 1.0}

#: Order of the CSCM parameters after the common block (see layout.py).
PARAM_NAMES = (
    "alpha", "theta", "lamda", "beta",
    "alpha1", "theta1", "lamda1", "beta1",
    "alpha2", "theta2", "lamda2", "beta2",
    "R", "X0", "W", "D1", "D2",
    "B", "D", "GFC", "GFT", "GFS", "pwrc", "pwrt", "pmod",
    "eta0c", "nc", "eta0t", "nt", "overc", "overt", "srate", "repow",
)


def _poly(x: float, a: float, b: float, c: float) -> float:
    """``a x^2 + b x + c`` (the notes' P(x; A, B, C))."""
    return (a * x + b) * x + c


def elastic_moduli(fc: float) -> tuple[float, float]:
    """Default bulk and shear modulus from f'c.

    .. math:: E = E_C\\,(f'_c / 10\\,\\mathrm{MPa})^{1/3},\\quad
              E_C = 18.275\\ \\mathrm{GPa},\\quad \\nu = 0.15,\\quad
              K = \\frac{E}{3(1-2\\nu)},\\ G = \\frac{E}{2(1+\\nu)}

    Murray 2007 (FHWA-HRT-05-062) ch. 2 "Bulk and shear moduli" [V]
    (notes sec. 2.2; the manual prints E_C in MPa, a unit typo for GPa).

    Parameters
    ----------
    fc : float
        Unconfined compression strength f'c [Pa], > 0.

    Returns
    -------
    (K, G) : tuple of float, [Pa].
    """
    E = 18.275e9 * (fc / (10.0 * MPA)) ** (1.0 / 3.0)
    return E / (3.0 * (1.0 - 2.0 * NU)), E / (2.0 * (1.0 + NU))


def fracture_energy_tension(fc: float, dagg: float) -> float:
    """Default tensile fracture energy GFT [J/m^2].

    .. math:: G_{FT} = G_{F0}(d)\\,(f'_c/10\\,\\mathrm{MPa})^{0.7},\\quad
              G_{F0} = 0.046875 d^2 - 0.5 d + 26\\ \\mathrm{N/m}\\ (d\\ \\mathrm{in\\ mm})

    **[R/D] reconstruction, not verified** (notes sec. 2.2/2.3): CEB-FIP
    MC90 (GF0 = 25/30/58 N/m at 8/16/32 mm) interpolated by the quadratic.
    The notes show it gives 69.5 J/m^2 at f'c = 43.1 MPa, dagg = 8 mm, not
    the paper's 83.25 J/m^2 (which matches dagg = 16 mm). Give ``GFT``
    explicitly to use another value.

    Parameters
    ----------
    fc : float
        f'c [Pa].
    dagg : float
        Maximum aggregate size [m].
    """
    d = dagg * 1e3
    gf0 = _poly(d, 0.046875, -0.5, 26.0)
    return gf0 * (fc / (10.0 * MPA)) ** 0.7


def default_parameters(fc: float, dagg: float, **overrides: float) -> dict[str, float]:
    """Full CSCM parameter set (SI) from f'c and aggregate size.

    Fits of notes sec. 2.2 (Murray 2007 defaults as transcribed; each fit
    P(fc; a, b, c) = a fc^2 + b fc + c with fc in MPa unless noted, tags in
    the comments below). Valid range of the defaults: 20-58 MPa [V].

    Parameters
    ----------
    fc : float
        Unconfined compression strength f'c [Pa].
    dagg : float
        Maximum aggregate size [m].
    **overrides
        Any of :data:`PARAM_NAMES` or ``K``, ``G`` in SI units; replaces the
        generated value. Unknown names raise ``ValueError``.

    Returns
    -------
    dict
        ``K, G`` and every name of :data:`PARAM_NAMES`, SI units.
    """
    if not (fc > 0.0 and math.isfinite(fc)):
        raise ValueError(f"cscm: fc must be a positive number of pascals, got {fc!r}")
    if not (dagg > 0.0 and math.isfinite(dagg)):
        raise ValueError(f"cscm: aggregate_size must be positive [m], got {dagg!r}")
    f = fc / MPA                      # the fits take MPa ...
    fpsi = f * PSI_PER_MPA            # ... and the fluidity fits psi
    K, G = elastic_moduli(fc)
    gft = fracture_energy_tension(fc, dagg)
    out = {
        "K": K, "G": G,
        # TXC shear surface [S]
        "alpha": _poly(f, -0.003, 0.3169747, 7.7047) * MPA,
        "theta": _poly(f, 1.3216e-5, 2.3548e-3, 0.2140058),
        "lamda": 10.5 * MPA,
        "beta": 1.929e-2 / MPA,
        # Rubin ratios [S]
        "alpha1": 0.74735,
        "theta1": _poly(f, -4.0856e-7, -1.2132e-6, 1.5593e-3) / MPA,
        "lamda1": 0.17,
        "beta1": _poly(f, -1.9972e-5, 2.2655e-4, 8.1748e-2) / MPA,
        "alpha2": 0.66,
        "theta2": _poly(f, -4.8697e-7, -1.8883e-6, 1.8822e-3) / MPA,
        "lamda2": 0.16,
        "beta2": _poly(f, -1.9972e-5, 2.2655e-4, 8.2748e-2) / MPA,
        # cap [S]
        "R": 5.0,
        "X0": _poly(f, 8.769178e-3, -7.3302306e-2, 84.85) * MPA,
        "W": 0.05,
        "D1": 2.5e-4 / MPA,
        "D2": 3.49e-7 / MPA ** 2,
        # damage [S]; GFS = GFT, GFC = 100 GFT [V 05-063 ch.10]
        "B": CONSTANT_DEFAULTS["B"],
        "D": CONSTANT_DEFAULTS["D"],
        "GFT": gft,
        "GFS": gft,
        "GFC": GFC_PER_GFT * gft,
        "pwrc": CONSTANT_DEFAULTS["pwrc"],
        "pwrt": CONSTANT_DEFAULTS["pwrt"],
        "pmod": 0.0,
        # rate effects [S + numeric check]; eta0 fits in psi, time in s
        "eta0c": _poly(fpsi, 1.2772337e-11, -1.0613722e-7, 3.203497e-4),
        "nc": 0.78,
        "eta0t": _poly(fpsi, 8.0614774e-13, -9.77736719e-10, 5.0752351e-5),
        "nt": 0.48,
        "overc": _poly(f, 1.309663e-2, -0.3927659, 21.45) * MPA,
        "overt": _poly(f, 1.309663e-2, -0.3927659, 21.45) * MPA,
        "srate": CONSTANT_DEFAULTS["srate"],
        "repow": CONSTANT_DEFAULTS["repow"],
    }
    for key, value in overrides.items():
        if value is None:
            continue
        if key not in out:
            raise ValueError(f"cscm: unknown parameter {key!r}; known: "
                             f"{', '.join(out)}")
        out[key] = float(value)
    return out
