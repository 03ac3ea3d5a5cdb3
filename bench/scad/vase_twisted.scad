// A twisted vase: a wavy star extruded with a twist and a taper, hollowed by a smaller star in
// phase (the same twist and taper per unit height, so the wall keeps its thickness), a floor.
h = 60; twist = 120; slices = 60;
module star(r, n = 9) {
  polygon([for (i = [0:4 * n - 1]) let(a = i * 360 / (4 * n), rr = r * (1 + 0.12 * cos(n * a))) [rr * cos(a), rr * sin(a)]]);
}
module body(k = 1, r = 20) {
  linear_extrude(height = h * k, twist = twist * k, slices = round(slices * k), scale = 1 + 0.3 * k)
    star(r);
}
union() {
  difference() {
    body();
    body(1.1, 18);
  }
  intersection() {
    body();
    translate([0, 0, -1]) cube([200, 200, 8], center = true);
  }
}
