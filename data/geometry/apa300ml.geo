// A parametric amplified piezo actuator (APA300ML-like): gmsh script, OpenCASCADE kernel, mm.
//
// The shell is drawn in the x-y plane and extruded along z (its width):
//   - two end blocks at x = +-(stack_length/2 + seat_height .. + end_thickness), |y| <= end_height/2,
//     each with a stack seat on its inner face: a seat_size x seat_size pad, seat_height thick,
//     whose face (x = +-stack_length/2) is where the stacks push. The stack cavity between the
//     seats is empty (the stacks are added as beams between remote points, see docs/apa300ml.md);
//   - two interface blocks (the mechanical interfaces) at y = +-height/2, |x| <= interface_length/2,
//     interface_thickness thick;
//   - four straight blades of blade_thickness joining the top (bottom) of each end block to the
//     interface blocks: the lever. The shell contracts along y when the stacks push its ends apart;
//     the amplification is about (horizontal run)/(vertical rise) of the blades.
// Axes: x along the stacks, y the actuation axis (top interface at y = +height/2), z the width.
//
// Every dimension is a DefineConstant: override with `gmsh -setnumber NAME VALUE`, or with
// `piezobench superelement from-step apa300ml.geo --geo-parameter NAME=VALUE`.
// The defaults and how close they come to the APA300ML's figures: docs/apa300ml.md.
SetFactory("OpenCASCADE");

DefineConstant[
  stack_length = {60, Name "Parameters/stack cavity length (3 stacks x 20 mm), mm"},
  width = {20, Name "Parameters/shell width (z), mm"},
  end_thickness = {6, Name "Parameters/end block thickness (x), mm"},
  end_height = {14, Name "Parameters/end block height (y), mm"},
  height = {40, Name "Parameters/height between the interfaces (y), mm"},
  interface_length = {16, Name "Parameters/interface block length (x), mm"},
  interface_thickness = {9, Name "Parameters/interface block thickness (y), mm"},
  blade_thickness = {1.06, Name "Parameters/blade thickness, mm"},
  blade_inset = {1.5, Name "Parameters/blade root inset from the end block's outer face (x), mm"},
  seat_size = {10, Name "Parameters/stack seat, square side (y, z), mm"},
  seat_height = {1, Name "Parameters/stack seat height (x), mm"}
];

xs = stack_length / 2;            // the seats' faces: the stack ends
xe = xs + seat_height;            // inner face of the end blocks
xo = xe + end_thickness;          // outer face of the end blocks
ye = end_height / 2;              // top of the end blocks
yi = height / 2 - interface_thickness;  // underside of the top interface block
xi = interface_length / 2;
t = blade_thickness;

// Blocks.
Box(1) = {xe, -ye, -width / 2, end_thickness, end_height, width};
Box(2) = {-xo, -ye, -width / 2, end_thickness, end_height, width};
Box(5) = {xs, -seat_size / 2, -seat_size / 2, seat_height + 0.5, seat_size, seat_size};
Box(6) = {-xe - 0.5, -seat_size / 2, -seat_size / 2, seat_height + 0.5, seat_size, seat_size};
Box(3) = {-xi, yi, -width / 2, interface_length, interface_thickness, width};
Box(4) = {-xi, -height / 2, -width / 2, interface_length, interface_thickness, width};

// A blade: centreline from (ax, ay) to (bx, by), both ends sunk t into the blocks they join.
Macro Blade
  dx = bx - ax; dy = by - ay; len = Sqrt(dx * dx + dy * dy);
  nx = -dy / len * t / 2; ny = dx / len * t / 2;
  p1 = newp; Point(p1) = {ax + nx, ay + ny, -width / 2};
  p2 = newp; Point(p2) = {bx + nx, by + ny, -width / 2};
  p3 = newp; Point(p3) = {bx - nx, by - ny, -width / 2};
  p4 = newp; Point(p4) = {ax - nx, ay - ny, -width / 2};
  l1 = newl; Line(l1) = {p1, p2};
  l2 = newl; Line(l2) = {p2, p3};
  l3 = newl; Line(l3) = {p3, p4};
  l4 = newl; Line(l4) = {p4, p1};
  cl = newll; Curve Loop(cl) = {l1, l2, l3, l4};
  s = news; Plane Surface(s) = {cl};
  ex[] = Extrude {0, 0, width} { Surface{s}; };
  blades[] += ex[1];
Return

blades[] = {};
ax = xo - blade_inset; ay = ye - t; bx = xi - t; by = yi + t; Call Blade;
ax = -(xo - blade_inset); bx = -(xi - t); Call Blade;
ay = -(ye - t); by = -(yi + t); Call Blade;
ax = xo - blade_inset; bx = xi - t; Call Blade;

BooleanUnion{ Volume{1}; Delete; }{ Volume{2, 3, 4, 5, 6, blades[]}; Delete; }
