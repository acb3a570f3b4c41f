"""The paper's disc (Husek et al. 2017, sec. 3) as an LS-DYNA keyword deck.

Writes, in mm, ms, kg (stress GPa, force kN, energy J):

* ``examples/lsdyna/disc_impact.k``: the model (the part, its SPH section,
  ``*MAT_CSCM`` with every parameter, the initial velocity, the rigid base,
  the end time and the output rate), which includes
* ``disc_impact_particles.k``: the 10,112 particles as ``*NODE`` and
  ``*ELEMENT_SPH`` (0.9 MB; written here, not kept in the repository),

from the lattice and the material of examples/disc_impact.toml. Then::

    python examples/lsdyna/disc_impact.py
    sphdyn run examples/lsdyna/disc_impact.k --units mm-ms-kg

The material is the TOML deck's CSCM in MAT_159's full form: the paper's
K, G and fracture energies, every other parameter sphdyn's default fit for
f'c = 43.1 MPa and an 8 mm aggregate, IRATE = 1. What LS-DYNA's keywords
cannot say (the TOML deck's calibrated rate_thresholds, its wall stiffness
and smoothing-length rule) the imported deck takes at sphdyn's defaults;
docs/lsdyna.md lists them, and tests/test_lsdyna_import.py runs the import
against the TOML deck with the same choices.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
TOML = HERE.parent / "disc_impact.toml"

#: *MAT_CSCM's cards in order: sphdyn's parameter names and each one's
#: factor from SI into mm-ms-kg (stress GPa, length mm, time ms)
GPA, MM, MS = 1e-9, 1e3, 1e3
CARDS = (("G", GPA), ("K", GPA), ("alpha", GPA), ("theta", 1.0), ("lamda", GPA),
         ("beta", 1 / GPA), ("NH", 1.0), ("CH", 1.0)), \
        (("alpha1", 1.0), ("theta1", 1 / GPA), ("lamda1", 1.0), ("beta1", 1 / GPA),
         ("alpha2", 1.0), ("theta2", 1 / GPA), ("lamda2", 1.0), ("beta2", 1 / GPA)), \
        (("R", 1.0), ("X0", GPA), ("W", 1.0), ("D1", 1 / GPA), ("D2", 1 / GPA ** 2)), \
        (("B", 1.0), ("GFC", GPA * MM), ("D", 1.0), ("GFT", GPA * MM), ("GFS", GPA * MM),
         ("pwrc", 1.0), ("pwrt", 1.0), ("PMOD", 1.0)), \
        (("eta0c", None), ("nc", 1.0), ("eta0t", None), ("nt", 1.0), ("overc", GPA),
         ("overt", GPA), ("srate", 1.0), ("repow", 1.0))


def _deck():
    sys.path.insert(0, str(HERE.parents[1] / "src"))
    from sphdyn.deck import load_deck

    return load_deck(TOML)


def particles() -> tuple:
    """The TOML deck's particle positions [m] and mass [kg]."""
    from sphdyn.build.model import build_model

    model = build_model(_deck())
    return model.particles.x, float(model.particles.m[0])


def cscm_cards() -> list[str]:
    """*MAT_CSCM's data cards (after MID ... ITRETRC and PRED) in mm-ms-kg."""
    from sphdyn.materials.cscm.defaults import default_parameters

    mat = next(m for m in _deck().material if m.name == "concrete")
    p = default_parameters(mat.fc, mat.aggregate_size, K=mat.K, G=mat.G, GFT=mat.GFT,
                           GFS=mat.GFS, GFC=mat.GFC)
    p |= {"NH": 0.0, "CH": 0.0, "PMOD": 0.0}
    # the fluidities eta0 [s^(1 - n)]: eta = eta0 / rate^n is a time
    factor = {"eta0c": MS ** (1 - p["nc"]), "eta0t": MS ** (1 - p["nt"])}
    return [",".join(repr(float(f"{p[k] * (f if f else factor[k]):.15g}"))
                     for k, f in card) for card in CARDS]


def model_text() -> str:
    """The text of disc_impact.k."""
    return "\n".join([
        "$ The paper's disc (Husek et al. 2017, sec. 3, Fig. 3): a concrete disc strikes",
        "$ a rigid base at 15 m/s. Units mm, ms, kg (stress GPa, force kN). Written by",
        "$ examples/lsdyna/disc_impact.py, which also writes the particles' include.",
        "*KEYWORD",
        "*TITLE",
        "Disc striking a rigid base at 15 m/s (Husek et al. 2017, CSCM concrete)",
        "*INCLUDE",
        "disc_impact_particles.k",
        "*PART",
        "disc",
        "1,1,1",
        "$    secid      cslh      hmin      hmax",
        "*SECTION_SPH",
        "1,1.2,0.5,2.0",
        "$ MAT_159 in full: the paper's K, G, GFT = GFS = 83.25 J/m^2, GFC = 100 GFT;",
        "$ the rest sphdyn's default fit for f'c = 43.1 MPa, dagg = 8 mm; IRATE = 1",
        "*MAT_CSCM_TITLE",
        "concrete",
        "$      mid        ro     nplot     incre     irate     erode     recov   itretrc",
        "1,2.4e-06,1,0.0,1,0.0,0.0,0",
        "$     pred",
        "0.0",
        *cscm_cards(),
        "*INITIAL_VELOCITY_GENERATION",
        "$       id      styp     omega        vx        vy        vz",
        "1,2,0.0,0.0,-15.0,0.0",
        "*RIGIDWALL_PLANAR",
        "0",
        "0.0,0.0,0.0,0.0,1.0,0.0,0.0",
        "*CONTROL_TERMINATION",
        "0.2",
        "*DATABASE_BINARY_D3PLOT",
        "0.01",
        "*END",
    ]) + "\n"


def particles_text() -> str:
    """The text of disc_impact_particles.k: nodes in mm (every digit), masses
    in kg."""
    x, m = particles()
    lines = ["*KEYWORD", "*NODE"]
    lines += [f"{k + 1},{float(p[0]) * MM!r},{float(p[1]) * MM!r},{float(p[2]) * MM!r}"
              for k, p in enumerate(x)]
    lines += ["*ELEMENT_SPH"]
    lines += [f"{k + 1},1,{m!r}" for k in range(x.shape[0])]
    return "\n".join(lines + ["*END"]) + "\n"


def main() -> None:
    (HERE / "disc_impact.k").write_text(model_text())
    (HERE / "disc_impact_particles.k").write_text(particles_text())
    print(f"wrote {HERE / 'disc_impact.k'} and disc_impact_particles.k")


if __name__ == "__main__":
    main()
