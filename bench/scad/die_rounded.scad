// A six-sided die with rounded edges (a cube cut by a sphere) and spherical pips.
size = 16; pip = 1.6; off = size / 4;
module pips(n) {
  spots = n == 1 ? [[0, 0]] : n == 2 ? [[-off, -off], [off, off]] : n == 3 ? [[-off, -off], [0, 0], [off, off]]
        : n == 4 ? [[-off, -off], [off, off], [-off, off], [off, -off]]
        : n == 5 ? [[-off, -off], [off, off], [-off, off], [off, -off], [0, 0]]
        : [[-off, -off], [off, off], [-off, off], [off, -off], [-off, 0], [off, 0]];
  for (s = spots) translate([s[0], s[1], size / 2]) sphere(r = pip, $fn = 24);
}
difference() {
  intersection() {
    cube(size, center = true);
    sphere(r = size * 0.72, $fn = 96);
  }
  pips(1);
  rotate([180, 0, 0]) pips(6);
  rotate([90, 0, 0]) pips(2);
  rotate([-90, 0, 0]) pips(5);
  rotate([0, 90, 0]) pips(3);
  rotate([0, -90, 0]) pips(4);
}
