"""Deck texts shared by several test modules."""


def concrete_disc_2d(dx: str, t_end: str, every: str, fields, seed: int = 0,
                     body: str = "", stiffness: str | None = None) -> str:
    """The paper's concrete disc (CSCM, f'c 43.1 MPa) in 2D on a rigid base.

    ``body``: extra lines of the [[body]] table (mass field, cracks);
    ``stiffness``: the wall's spring law (default: the deck default).
    """
    wall_law = "" if stiffness is None else f'stiffness = "{stiffness}"\n'
    field_list = ", ".join(f'"{f}"' for f in fields)
    return f"""
[run]
dimension = 2
t_end = "{t_end}"
seed = {seed}
[[material]]
name = "concrete"
model = "cscm"
density = 2400.0
fc = "43.1 MPa"
aggregate_size = "8 mm"
[[body]]
name = "disc"
material = "concrete"
dx = "{dx}"
velocity = [0, "-15 m/s"]
geometry = {{ shape = "cylinder", centre = [0, "50.1 mm"], radius = "50 mm" }}
{body}
[[wall]]
name = "base"
point = [0, 0]
normal = [0, 1]
{wall_law}[output]
every = "{every}"
progress = false
vtk = false
fields = [{field_list}]
"""


#: A rubber-like J2 disc (2D, dx = 1 mm, 316 particles) dropped on a floor at
#: 5 m/s; format keys ``t_end`` and ``ck`` (checkpoint_every).
SMALL_DISC = """
[run]
title = "small disc on a wall"
dimension = 2
t_end = "{t_end}"
[[material]]
name = "rubber"
model = "j2"
density = 1000.0
E = 1e7
nu = 0.3
yield_stress = 2e5
hardening_modulus = 1e6
[[body]]
name = "disc"
material = "rubber"
dx = 1e-3
velocity = [0, -5.0, 0]
geometry = {{ shape = "cylinder", centre = [0, 0.0062, 0], radius = 0.006 }}
[[wall]]
name = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]
[output]
every = "0.5 ms"
history_every = 2
checkpoint_every = {ck}
progress = false
fields = ["velocity", "stress", "von_mises", "plastic_strain", "damage"]
"""


#: An elastic steel [[material]] named "steel" (E 200 GPa, nu 0.3, 7850 kg/m^3).
STEEL = """[[material]]
name = "steel"
model = "elastic"
density = 7850.0
E = "200 GPa"
nu = 0.3
"""


#: rollers on the symmetry planes x = 0 and y = 0 of a quarter model of the
#: mesh "block" (node sets "x0" and "y0", each holding its normal direction)
ROLLERS = """
[[set]]
name = "x0"
mesh = "block"
region = {shape = "box", lo = [-1e-4, -1, -1], hi = [1e-4, 1, 1]}
[[set]]
name = "y0"
mesh = "block"
region = {shape = "box", lo = [-1, -1e-4, -1], hi = [1, 1e-4, 1]}
[[boundary]]
set = "x0"
type = "fixed"
components = ["x"]
[[boundary]]
set = "y0"
type = "fixed"
components = ["y"]
"""


def elastic_steel(dimension: int, t_end: str = "1 us") -> str:
    """A [run] of ``dimension`` and ``t_end`` and an elastic steel named
    "steel" (7850 kg/m^3, E 200 GPa, nu 0.3): the head of a test deck."""
    return f"""
[run]
dimension = {dimension}
t_end = "{t_end}"
[[material]]
name = "steel"
model = "elastic"
density = 7850
E = "200 GPa"
nu = 0.3
"""
