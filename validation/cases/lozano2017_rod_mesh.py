"""Write the drop weight of Lozano Mendoza & Makdesi Aphram (2017) as a hex8
mesh with its rounded tip: lozano2017_rod.inp (Abaqus, millimetres).

The rod of the tests (Loven & Svavarsdottir 2016, Table 5.1, read in
validation/data/loven2016_dropweight_rc_beams.csv): 10.1 kg, 80 mm across,
260 mm long, its striking end rounded with a radius of 400 mm. Here a
square rod of the same cross-section area (70.9 mm side: pi 40^2 = 70.9^2)
in 8 x 8 x 26 elements, its bottom face a spherical cap of radius 400 mm:
each node of the bottom layers is raised by R - sqrt(R^2 - r^2), r its
distance from the axis, fading linearly to none at the top (so the elements
stay regular). A flat face at the particles' spacing would strike the whole
face at once (a pulse of rho c v over the face, 62 MPa at 6.9 m/s, which
cracks the 100 mm beam through its depth); the cap starts the contact at
the centre, as in the test. The tip is at (590, 50, 0) mm; the deck moves it
with the file's coordinates as they are (length_unit = "1 mm") and places
it by its own z offset through the nodes here.

    python validation/cases/lozano2017_rod_mesh.py   (prints the mass check)
"""

from pathlib import Path

import numpy as np

SIDE, LENGTH, RADIUS_TIP = 70.9, 260.0, 400.0   # mm
N_SIDE, N_LENGTH = 8, 26
CENTRE, TIP_Z = (590.0, 50.0), 102.0             # mm: the tip 2 mm above the beam's face


def nodes_and_cells():
    xs = np.linspace(-SIDE / 2, SIDE / 2, N_SIDE + 1)
    zs = np.linspace(0.0, LENGTH, N_LENGTH + 1)
    X, Y, Z = np.meshgrid(xs, xs, zs, indexing="ij")
    r2 = X**2 + Y**2
    cap = RADIUS_TIP - np.sqrt(RADIUS_TIP**2 - r2)
    Z = Z + cap * (1.0 - Z / LENGTH)
    pts = np.column_stack([X.ravel() + CENTRE[0], Y.ravel() + CENTRE[1], Z.ravel() + TIP_Z])
    nid = np.arange(pts.shape[0]).reshape(X.shape)
    cells = []
    for i in range(N_SIDE):
        for j in range(N_SIDE):
            for k in range(N_LENGTH):
                cells.append([nid[i, j, k], nid[i + 1, j, k], nid[i + 1, j + 1, k], nid[i, j + 1, k],
                              nid[i, j, k + 1], nid[i + 1, j, k + 1], nid[i + 1, j + 1, k + 1],
                              nid[i, j + 1, k + 1]])
    return pts, np.array(cells)


def volume_mm3(pts, cells) -> float:
    """Volume of the hexahedra (each split into 6 tetrahedra)."""
    tets = ((0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6), (0, 4, 5, 6), (0, 5, 1, 6))
    v = 0.0
    for a, b, c, d in tets:
        p = pts[cells[:, [a, b, c, d]]]
        v += np.abs(np.einsum("ij,ij->i", p[:, 1] - p[:, 0],
                              np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))).sum() / 6.0
    return v


def main() -> None:
    pts, cells = nodes_and_cells()
    out = Path(__file__).with_name("lozano2017_rod.inp")
    lines = ["*HEADING", "Lozano & Makdesi 2017 drop weight, mm (validation/cases/lozano2017_rod_mesh.py)",
             "*NODE"]
    lines += [f"{i + 1}, {x:.6f}, {y:.6f}, {z:.6f}" for i, (x, y, z) in enumerate(pts)]
    lines.append("*ELEMENT, TYPE=C3D8R, ELSET=ROD")
    lines += [f"{e + 1}, " + ", ".join(str(n + 1) for n in c) for e, c in enumerate(cells)]
    out.write_text("\n".join(lines) + "\n")
    vol = volume_mm3(pts, cells) * 1e-9
    print(f"{out.name}: {len(pts)} nodes, {len(cells)} elements, volume {vol:.6e} m^3, "
          f"density for 10.1 kg: {10.1 / vol:.1f} kg/m^3")


if __name__ == "__main__":
    main()
