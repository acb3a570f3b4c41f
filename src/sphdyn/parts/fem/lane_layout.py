r"""Layout of the lane scratch of the vectorised hex8 passes (:mod:`.hex_lanes`).

The one-point hex8 passes work on :data:`LANES` elements side by side: every
per-element quantity is a row of ``LANES`` contiguous doubles in one flat
scratch per block of elements, so the compiled loops over the lanes are SIMD
loops (the layout LS-DYNA's element blocks use). The rows below are offsets
in units of ``LANES``; being module constants, Numba compiles them as
literals, so the compiler sees fixed distances between the rows and needs no
run-time alias checks.
"""

#: elements side by side (two AVX-512 or four AVX2 registers of doubles)
LANES = 16

X_ = 0  #: 24 rows: node coordinates relative to node 0, (I, k) -> X_ + 3 I + k [m]
VN_ = 24  #: 24 rows: node velocities at n + 1/2 [m/s]
G_ = 48  #: 24 rows: volume derivatives dV/dx_kI [m^2]
VOL_ = 72  #: volume [m^3]
INV_ = 73  #: 1 / volume (0 for a degenerate element) [1/m^3]
L_ = 74  #: 9 rows: velocity gradient L_ij -> L_ + 3 i + j [1/s]
SIG_ = 83  #: 9 rows: Cauchy stress [Pa]
DKK_ = 92  #: trace of the element's L [1/s]
RHO_ = 93  #: density [kg/m^3]
C_ = 94  #: wave speed [m/s]
HG_ = 95  #: 12 rows: stiffness-form hourglass forces (a, k) -> HG_ + 3 a + k [N]
F_ = 107  #: 24 rows: element nodal forces [N]
DT_ = 131  #: element stable step (with the hourglass control's terms) [s]
Q_ = 132  #: bulk-viscosity pressure [Pa]
HEAT_ = 133  #: bulk-viscosity heat of the step [J/kg]
POWER_ = 134  #: hourglass power [W]
FACE_ = 135  #: V^(2/3) [m^2]
COEF_ = 136  #: hourglass coefficient a_h or k_h (0 without hourglass control)
INVV_ = 137  #: 1 / V where hourglass control acts, else 0 [1/m^3]
LB_ = 138  #: 9 rows: sum_I v_iI dV/dx_jI [m^3/s]
M_ = 147  #: 9 rows: hourglass share M_ij = sum_a Q_ai h_aj / V [Pa]
QA_ = 156  #: 12 rows: hourglass generalised forces (a, k) -> QA_ + 3 a + k [N]
GM_ = 168  #: 32 rows: hourglass shape vectors gamma_aI -> GM_ + 8 a + I
ROW_ = 200  #: the largest Gershgorin row sum of their Gram matrix so far
ELL_ = 201  #: characteristic length of the element step [m]
TR_ = 202  #: the Gram matrix's trace
MSH_ = 203  #: each node's share of the element's mass (mass / 8) [kg]
OV_ = 204  #: the overlap of the stiffness's and hourglass control's subspaces
MX_ = 205  #: 3 rows: the mean node coordinates (relative to node 0) [m]
PX_ = 208  #: 6 rows: sum_I of the coordinates' products about the mean (00 01 02 11 12 22) [m^2]
RG_ = 214  #: 6 rows: sum_I of the volume derivatives' products (00 01 02 11 12 22) [m^4]
ROWS = 220  #: rows in all
