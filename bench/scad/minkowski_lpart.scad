// An L-shaped part with a round hole, grown by a faceted sphere: one distance sampling in pic eval.
minkowski() {
  difference() {
    cube([20, 14, 8]);
    translate([6, -1, 4]) cube([20, 16, 10]);
    translate([3, 7, -1]) cylinder(r = 2, h = 10, $fn = 24);
  }
  sphere(r = 1.5, $fn = 24);
}
