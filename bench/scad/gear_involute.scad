// An involute spur gear with many teeth and a bore: a Thingiverse staple.
teeth = 60; module_ = 1; pressure = 20; thickness = 6; bore = 8;
pitch_r = teeth * module_ / 2;
base_r = pitch_r * cos(pressure);
outer_r = pitch_r + module_;
root_r = pitch_r - 1.25 * module_;
function involute(r, t) = [r * (cos(t) + t * PI / 180 * sin(t)), r * (sin(t) - t * PI / 180 * cos(t))];
function rot(p, a) = [p[0] * cos(a) - p[1] * sin(a), p[0] * sin(a) + p[1] * cos(a)];
t_max = sqrt(pow(outer_r / base_r, 2) - 1) * 180 / PI;
half = 360 / teeth / 4 + (tan(pressure) - pressure * PI / 180) * 180 / PI;
module tooth() {
  steps = 8;
  left = [for (i = [0:steps]) rot(involute(base_r, t_max * i / steps), -half)];
  right = [for (i = [steps:-1:0]) let(p = involute(base_r, t_max * i / steps)) rot([p[0], -p[1]], half)];
  polygon(concat([[0, 0]], left, right));
}
difference() {
  linear_extrude(thickness) union() {
    circle(r = root_r, $fn = teeth * 4);
    for (i = [0:teeth - 1]) rotate(i * 360 / teeth) tooth();
  }
  translate([0, 0, -1]) cylinder(r = bore / 2, h = thickness + 2, $fn = 48);
}
