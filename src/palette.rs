//! The one palette: a colour per method, read by the recordings (3D, plots) and by the studies'
//! diagrams, so a method has the same colour everywhere.

/// One colour per method, the same in 3D, in every plot of every scene and in every diagram.
/// (ColorBrewer Set1, which stays distinguishable on the viewer's dark background.)
pub fn method_color(name: &str) -> [u8; 3] {
    match name {
        "explicit-euler" => [228, 26, 28],
        "semi-implicit-euler" => [255, 127, 0],
        "implicit-euler" => [152, 78, 163],
        "midpoint" => [166, 86, 40],
        "trapezoid" => [247, 129, 191],
        "rk4" => [55, 126, 184],
        "verlet" => [77, 175, 74],
        "ftl" => [0, 190, 190],
        "yoshida4" => [188, 189, 34],
        "dopri5" => [255, 215, 0],
        "dop853" => [90, 110, 255],
        "vern9" => [0, 128, 110],
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
