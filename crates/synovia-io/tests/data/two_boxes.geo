// Two unit cubes stacked along y, [0,1]x[0,1]x[0,1] (`lower`) and [0,1]x[1,2]x[0,1] (`upper`),
// extruded from two squares that share the curve y = 1 (a conforming interface), with boundary
// physical groups for the synovia-io Gmsh tests.
lc = 0.5;
Point(1) = {0, 0, 0, lc};
Point(2) = {1, 0, 0, lc};
Point(3) = {1, 1, 0, lc};
Point(4) = {0, 1, 0, lc};
Point(5) = {1, 2, 0, lc};
Point(6) = {0, 2, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {3, 5};
Line(6) = {5, 6};
Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, -3};
Plane Surface(2) = {2};
// Extrude returns [top surface, volume, lateral surfaces in the order of the curve loop].
low[] = Extrude {0, 0, 1} { Surface{1}; };
up[] = Extrude {0, 0, 1} { Surface{2}; };
Physical Volume("lower") = {low[1]};
Physical Volume("upper") = {up[1]};
Physical Surface("clamped_bottom") = {low[2]};
Physical Surface("contact_interface") = {low[4]};
Physical Surface("traction_top") = {up[3]};
Physical Surface("symmetry_back") = {1, 2};
Physical Surface("symmetry_front") = {low[0], up[0]};
