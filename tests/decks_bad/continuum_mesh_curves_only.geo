// A 2 x 1 m rectangle with physical groups of curves only, no Physical Surface (mesh of
// continuum_mesh_curves_only.dat): gmsh -2 -format msh41 continuum_mesh_curves_only.geo
// saves the line elements of the groups and none of the surface's quadrangles.
Point(1) = {0, 0, 0, 1}; Point(2) = {2, 0, 0, 1}; Point(3) = {2, 1, 0, 1}; Point(4) = {0, 1, 0, 1};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Curve("clamp") = {4};
Physical Curve("load") = {2};
