"""Post-processing and reference solutions: fragments and windowed contact forces
(fragments), uniaxial compression curves (compression), the exact Riemann
solution of an ideal gas (riemann)."""
