"""Deck sections [[probe]] and [output]: what is recorded and written.

Field and probe-quantity names come from the output-field registry
:mod:`sphdyn.fields`; ``output.fields`` is checked against it when a deck is
validated, so fields registered later are accepted.
"""

from typing import Annotated, Literal, Optional

from pydantic import AfterValidator, Field, Strict, StrictBool

from ...fields import allowed_fields, default_fields, probe_quantities
from ..messages import problem, suggest
from ..units import TIME
from ..values import Section, integer, quantity, reference_to


class Probe(Section):
    """[[probe]]: time history of a quantity over a set of particles or of a
    mesh's nodes (LS-DYNA's nodout)."""

    set: reference_to("set") = Field(description="Name of a [[set]].")
    quantities: tuple[Literal[probe_quantities()], ...] = Field(
        ("displacement_x", "displacement_y", "displacement_z", "velocity_x",
         "velocity_y", "velocity_z", "von_mises"),
        description="Quantities recorded (stress tension positive, pressure "
                    "positive in compression; plastic_strain needs a j2 "
                    "material). Mesh nodes have position, velocity, speed, "
                    "displacement and mass (the default: without von_mises).")
    reduce: Literal["mean", "min", "max"] = Field(
        "mean", description="Reduction over the set's particles or nodes; history "
                            "columns are named probe_<set>_<quantity>.")


def known_field(name: str) -> str:
    """After-validator: ``name`` is a registered output field."""
    allowed = allowed_fields()
    if name not in allowed:
        raise problem(f"'{name}' is not an output field",
                      suggest(name, allowed, "use one of the known "
                              f"fields: {', '.join(allowed)}"))
    return name


class Output(Section):
    """[output]: frames, histories and checkpoints."""

    every: Optional[quantity(TIME, "frame interval", lo=0, lo_open=True)] = \
        Field(None, description="Time between frames (absent: t_end / 50).")
    vtk: StrictBool = Field(True, description="Also write VTK (.vtu) frames "
                                              "for ParaView.")
    fields: tuple[Annotated[str, Strict(), AfterValidator(known_field)],
                  ...] = Field(default_fields(),
                               description="Fields written in frames: the "
                               "particles' (those of the particle fields), and "
                               "each mesh's cells' (those of the cell fields "
                               "it has, besides its materials' history "
                               "columns, always written). See the output "
                               "fields below.")
    history_every: integer("step count", lo=1) = Field(
        10, description="Steps between history records (energies, contact "
                        "forces).")
    checkpoint_every: integer("step count", lo=0) = Field(
        0, description="Steps between checkpoints (0 = off).")
    force_window: quantity(TIME, "force averaging window", lo=0, lo_open=True) = Field(
        5e-6, description="Window of the averaged wall force: summary.json and "
                          "the ensemble table report, next to the raw peak, the "
                          "peak of the mean force over this window (from the "
                          "wall impulse I_wall_<name>), which smooths the "
                          "spikes of first contact.")
    progress: StrictBool = Field(True, description="Show a progress bar.")
    interaction_work: StrictBool = Field(
        False, description="Book the work of each interaction (contact, coupling, "
                           "wall, sublayer) apart, as history columns "
                           "W_contact_<name> [J], and the events' changes of the "
                           "loads (erosion) as W_contact_events; their sum is "
                           "-E_contact (LS-DYNA's sleout). A diagnosis switch: it "
                           "keeps one acceleration array per interaction and part.")
