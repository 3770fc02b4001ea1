// Small 2D test plate for fricbound's Gmsh reader: a 0.2 m x 0.05 m plate made of a
// quadrangle-meshed part and a triangle-meshed part, with boundary groups.
// Regenerate: gmsh plate.geo -2 -format msh41 -o plate-ascii.msh
//             gmsh plate.geo -2 -format msh41 -bin -o plate-binary.msh
Point(1) = {0, 0, 0};
Point(2) = {0.1, 0, 0};
Point(3) = {0.2, 0, 0};
Point(4) = {0.2, 0.05, 0};
Point(5) = {0.1, 0.05, 0};
Point(6) = {0, 0.05, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(2) = {2};
Transfinite Curve{1, 5} = 9;
Transfinite Curve{6, 7} = 4;
Transfinite Surface{1};
Recombine Surface{1};
Mesh.CharacteristicLengthMax = 0.02;
Physical Surface("quads") = {1};
Physical Surface("triangles") = {2};
Physical Curve("clamp") = {6};
Physical Curve("tip_edge") = {3};
Physical Point("corner") = {4};
