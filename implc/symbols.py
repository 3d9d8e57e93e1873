"""The symbols every stage shares: the point (x, y, z), the ray direction and the ray parameter."""

import sympy

X, Y, Z = sympy.symbols("x y z", real=True)
DX, DY, DZ = sympy.symbols("dx dy dz", real=True)
T = sympy.Symbol("t", real=True)

POINT = (X, Y, Z)
DIRECTION = (DX, DY, DZ)
