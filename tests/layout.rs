//! The layout a recording opens with, read back from the written file's blueprint store: legends
//! placed or hidden per plot, and each 3D view's eye framing what the scene drew.

#![cfg(feature = "rerun")]

mod common;

use std::collections::BTreeMap;

use common::{drawn_rows, physlab, scratch_dir};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::external::re_sdk_types::blueprint::archetypes::{
    EyeControls3D, PlotLegend, ViewBlueprint,
};
use rerun::log::{Chunk, LogMsg};

/// The view properties of a recording's blueprint, by the view's space origin: (property
/// archetype name, chunk).
fn view_properties(path: &std::path::Path) -> BTreeMap<String, Vec<(String, Chunk)>> {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let origin = ViewBlueprint::descriptor_space_origin().component;
    let mut origins = BTreeMap::new(); // view path → origin
    let mut properties = Vec::new(); // (view path, property name, chunk)
    for msg in DecoderApp::decode_lazy(file) {
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
            continue;
        };
        if !store_id.is_blueprint() {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
        let entity = chunk.entity_path().to_string();
        let parts: Vec<&str> = entity.trim_start_matches('/').split('/').collect();
        match parts[..] {
            ["view", _] => {
                if let Some(o) = chunk.iter_slices::<String>(origin).next() {
                    origins.insert(entity.clone(), o[0].to_string());
                }
            }
            ["view", id, name] if name != "ViewContents" => {
                properties.push((format!("/view/{id}"), name.to_string(), chunk));
            }
            _ => {}
        }
    }
    let mut by_origin: BTreeMap<String, Vec<(String, Chunk)>> = BTreeMap::new();
    for (view, name, chunk) in properties {
        let origin = origins
            .get(&view)
            .expect("a property of a view in the layout");
        by_origin
            .entry(origin.clone())
            .or_default()
            .push((name, chunk));
    }
    by_origin
}

fn vec3(chunk: &Chunk, descriptor: rerun::ComponentDescriptor) -> glam::Vec3 {
    let v = chunk
        .iter_slices::<[f32; 3]>(descriptor.component)
        .next()
        .unwrap_or_else(|| panic!("{} missing", descriptor.component));
    glam::Vec3::from_array(v[0])
}

/// Rerun's default vertical field of view for a 3D eye.
const FOV_Y_DEGREES: f32 = 55.0;
/// Width / height of the rope's 3D view at 1600×1000 (700 × 590 px in a viewer screenshot).
const ROPE_VIEW_ASPECT: f32 = 1.19;

/// A point's place in the view, (−1, −1) to (1, 1) from corner to corner when visible.
fn project(p: glam::Vec3, eye: glam::Vec3, target: glam::Vec3, up: glam::Vec3) -> (f32, f32) {
    let back = (eye - target).normalize();
    let right = up.cross(back).normalize();
    let up = back.cross(right);
    let d = p - eye;
    let depth = -d.dot(back);
    assert!(depth > 0.0, "{p} is behind the eye");
    let tan = (0.5 * FOV_Y_DEGREES.to_radians()).tan();
    (
        d.dot(right) / depth / (tan * ROPE_VIEW_ASPECT),
        d.dot(up) / depth / tan,
    )
}

#[test]
fn rope_recording_opens_with_its_legends_placed_and_its_ropes_framed() {
    let dir = scratch_dir("layout");
    let out = dir.join("r.rrd");
    let (code, stdout, stderr) = physlab(&["rope", "-q", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let props = view_properties(&out);

    // Legends: in the corner the default run's curves leave empty, or hidden.
    let corner = PlotLegend::descriptor_corner().component;
    let visible = PlotLegend::descriptor_visible().component;
    let legend = |plot: &str| -> (Option<u8>, bool) {
        let list = &props[&format!("/rope/plots/{plot}")];
        let (_, chunk) = list.iter().find(|(n, _)| n == "PlotLegend").unwrap();
        (
            chunk.iter_slices::<u8>(corner).next().map(|c| c[0]),
            chunk.iter_slices::<bool>(visible).next().unwrap().value(0),
        )
    };
    // Corner2D: 1 left top, 2 right top, 3 left bottom, 4 right bottom.
    assert_eq!(legend("energy"), (Some(2), true));
    assert_eq!(legend("log10_energy_change"), (Some(4), true));
    assert_eq!(legend("max_strain"), (Some(2), true));

    // The eye: z up, and every node of every rope in every frame, the pins and the stage inside
    // the view, the drawing spanning at least 80% of its width or height.
    let (_, eye) = props["/rope"]
        .iter()
        .find(|(n, _)| n == "EyeControls3D")
        .expect("the rope's 3D view has an eye");
    let position = vec3(eye, EyeControls3D::descriptor_position());
    let target = vec3(eye, EyeControls3D::descriptor_look_target());
    let up = vec3(eye, EyeControls3D::descriptor_eye_up());
    assert_eq!(up, glam::Vec3::Z);
    let points: Vec<glam::Vec3> = drawn_rows(&out, "/rope/")
        .iter()
        .flat_map(|(_, row)| row.iter().map(|p| glam::Vec3::from_array(*p)))
        .collect();
    assert!(points.len() > 10_000, "{} points drawn", points.len());
    let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
    for p in points {
        let (x, y) = project(p, position, target, up);
        assert!(x.abs() <= 1.0 && y.abs() <= 1.0, "{p} is outside the view");
        lo = lo.min(glam::Vec2::new(x, y));
        hi = hi.max(glam::Vec2::new(x, y));
    }
    let span = 0.5 * (hi - lo);
    assert!(
        span.max_element() >= 0.8,
        "the rope fills {:.0}% × {:.0}% of the view",
        100.0 * span.x,
        100.0 * span.y
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
