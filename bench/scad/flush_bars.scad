// Ten bars minus ten crossing bars of the same height: flush top and bottom faces.
difference() {
  union() for (i = [0:9]) translate([0, 2 * i, 0]) cube([20, 1, 1]);
  union() for (i = [0:9]) translate([2 * i + 0.5, 0, 0]) cube([1, 19, 1]);
}
