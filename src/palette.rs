//! The one palette: a colour per method, read by the recordings (3D, plots) and by the studies'
//! diagrams, so a method has the same colour everywhere.

/// One colour per method, the same in 3D, in every plot of every scene and in every diagram.
/// The default methods of the pendulum and the rope take seven hues far apart on the colour
/// wheel (red, orange, yellow, green, cyan, blue, violet), bright enough for the viewer's dark
/// background; the others differ from those in lightness as well as hue, and the hair's two
/// defaults (verlet, ftl) are green and pink.
pub fn method_color(name: &str) -> [u8; 3] {
    match name {
        "explicit-euler" => [235, 50, 50],
        "semi-implicit-euler" => [255, 145, 0],
        "midpoint" => [235, 220, 40],
        "verlet" => [60, 190, 60],
        "trapezoid" => [0, 205, 215],
        "rk4" => [70, 125, 255],
        "implicit-euler" => [190, 90, 240],
        "ftl" => [255, 105, 180],
        "yoshida4" => [150, 150, 60],
        "yoshida6" => [255, 255, 165],
        "kahan-li8" => [175, 250, 40],
        "sofroniou10" => [220, 160, 250],
        "dopri5" => [255, 190, 150],
        "dop853" => [160, 200, 255],
        "vern9" => [130, 255, 170],
        "rkn4" => [150, 75, 0],
        "dprkn6" => [0, 255, 0],
        "dprkn8" => [30, 150, 105],
        "dprkn12" => [0, 0, 255],
        "exact" | "reference" => [220, 220, 220],
        // A name without a colour of its own still gets a distinct, stable one.
        other => {
            let h = other.bytes().fold(2166136261u32, |h, b| {
                (h ^ u32::from(b)).wrapping_mul(16777619)
            });
            [
                96 + (h & 0x9f) as u8,
                96 + ((h >> 8) & 0x9f) as u8,
                96 + ((h >> 16) & 0x9f) as u8,
            ]
        }
    }
}
