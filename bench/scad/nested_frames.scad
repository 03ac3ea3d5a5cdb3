// 17 nested box frames (OpenSCAD's box-frame idiom): each cube minus three cutters flush with
// three of its faces, leaving its 12 edges 0.5 thick.
w = 0.5;
union() for (h = [1:17])
  difference() { cube(h); cube([h, h - w, h - w]); cube([h - w, h, h - w]); cube([h - w, h - w, h]); }
