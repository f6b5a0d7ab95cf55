// Two 1 x 0.5 m blocks 0.25 m apart, 2 x 1 quadrangles each (mesh of
// continuum_body_unheld.dat): gmsh -2 -format msh41 continuum_body_unheld.geo
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 0.5, 0}; Point(4) = {0, 0.5, 0};
Point(5) = {0, 0.75, 0}; Point(6) = {1, 0.75, 0}; Point(7) = {1, 1.25, 0}; Point(8) = {0, 1.25, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Transfinite Curve{1, 3, 5, 7} = 3; Transfinite Curve{2, 4, 6, 8} = 2;
Transfinite Surface{1, 2}; Recombine Surface{1, 2};
Physical Surface("blocks") = {1, 2};
Physical Curve("base") = {1};
Physical Curve("top") = {7};
