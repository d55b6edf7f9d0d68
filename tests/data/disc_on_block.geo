// A half-disc (radius 0.5, centre (1, 1.5)) resting on a block [0, 2] x [0, 1]: two separate
// bodies touching at (1, 1), for tests/suite/gmsh_solve.rs (meshed there with the gmsh CLI).
// Bodies `upper` and `lower`; boundary groups `prescribed_top` (the flat side of the disc),
// `contact_upper` (its arc), `contact_lower` (the top of the block), `clamped_base`.
Geometry.AutoCoherence = 0; // keep the two touching points (1, 1) apart: two bodies
lc = 0.12;
lf = 0.03;
Point(1) = {0, 0, 0, lc};
Point(2) = {2, 0, 0, lc};
Point(3) = {2, 1, 0, lc};
Point(4) = {1, 1, 0, lf};
Point(5) = {0, 1, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Point(11) = {1, 1.5, 0, lc};
Point(12) = {0.5, 1.5, 0, lc};
Point(13) = {1, 1, 0, lf};
Point(14) = {1.5, 1.5, 0, lc};
Circle(11) = {12, 11, 13};
Circle(12) = {13, 11, 14};
Line(13) = {14, 12};
Curve Loop(2) = {11, 12, 13};
Plane Surface(2) = {2};

Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
Physical Curve("clamped_base") = {1};
Physical Curve("contact_lower") = {3, 4};
Physical Curve("contact_upper") = {11, 12};
Physical Curve("prescribed_top") = {13};
