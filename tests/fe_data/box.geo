// Small 3D test box for fricbound's Gmsh reader: 0.1 x 0.02 x 0.01 m of hexahedra.
// Regenerate: gmsh box.geo -3 -format msh41 -bin -o box-hex-binary.msh
SetFactory("Built-in");
Point(1) = {0, 0, 0};
Point(2) = {0.1, 0, 0};
Point(3) = {0.1, 0.02, 0};
Point(4) = {0, 0.02, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 6;
Transfinite Curve{2, 4} = 3;
Transfinite Surface{1};
Recombine Surface{1};
out[] = Extrude {0, 0, 0.01} { Surface{1}; Layers{2}; Recombine; };
Physical Volume("solid") = {out[1]};
Physical Surface("root") = {out[5]};
Physical Surface("end") = {out[3]};
