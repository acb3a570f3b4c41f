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
