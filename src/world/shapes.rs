//! Scene description: shapes with procedural materials, as data (built-in or JSON), and the f64
//! ray intersection the CPU ground truth uses. The GPU twin is shaders/scene/raytrace.frag.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Largest number of objects the GPU tracer takes (uniform arrays).
pub const MAX_OBJECTS: usize = 32;

/// How far past its bounds a plane still counts as hit, relative to the hit's largest coordinate
/// (plus 1e-5 m). Planes that share an edge (the demo's floor meets its wall at y = 1.2, z = 6)
/// would otherwise both miss a ray through the edge: each hit lies on the other's bound, and
/// rounding puts it just outside either. At 320 x 240 and 64 x 48 a whole row of pixel centres
/// lies on that edge (issue 47). f32 puts a hit within a few 1e-7 of its magnitude, f64 far
/// closer, so 1e-5 closes the crack on both tracers and widens a plane by under 0.1 mm at 6 m.
pub const EDGE_SLACK: f64 = 1e-5;

/// A primitive of a ground-truth scene, world coordinates (GL axes: y up, -z forward).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum Shape {
    /// Plane through `point` with `normal`, kept where the hit lies inside the world-space box
    /// [`bounds_min`, `bounds_max`] (use +-1e30 for unbounded axes), closed and widened by
    /// [`EDGE_SLACK`] of the hit's magnitude.
    Plane {
        /// A point on the plane.
        point: [f64; 3],
        /// Its normal (any length > 0).
        normal: [f64; 3],
        /// The box's lower corner.
        bounds_min: [f64; 3],
        /// The box's upper corner.
        bounds_max: [f64; 3],
    },
    /// A sphere.
    Sphere {
        /// Its centre.
        center: [f64; 3],
        /// Its radius (> 0).
        radius: f64,
    },
    /// Axis-aligned box.
    Cuboid {
        /// The lower corner.
        min: [f64; 3],
        /// The upper corner.
        max: [f64; 3],
    },
}

/// A shape and its procedural pattern (0..=3, see `pattern_color`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Object {
    /// The geometry.
    pub shape: Shape,
    /// The procedural colour pattern, 0..=3.
    pub pattern: u8,
}

/// A ground-truth scene: named objects, traced exactly (f64 here, f32 in the GPU tracer).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// Its name (`demo`, `boxes`, or the JSON file's).
    pub name: String,
    /// At most [`MAX_OBJECTS`] objects.
    pub objects: Vec<Object>,
}

/// A ray hit: ray parameter, pattern and world point.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Ray parameter: the hit is at origin + t dir.
    pub t: f64,
    /// The object's pattern.
    pub material: u8,
    /// The world point hit.
    pub p: [f64; 3],
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Shape {
    /// Smallest t > 1e-9 where origin + t dir meets the shape.
    pub fn intersect(&self, o: [f64; 3], d: [f64; 3]) -> Option<f64> {
        let at = |t: f64| [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
        let ok = |t: f64| t > 1e-9 && t.is_finite();
        match *self {
            Shape::Plane {
                point,
                normal,
                bounds_min,
                bounds_max,
            } => {
                let den = dot(normal, d);
                if den.abs() <= 1e-12 {
                    return None;
                }
                let t = dot(normal, [point[0] - o[0], point[1] - o[1], point[2] - o[2]]) / den;
                let p = at(t);
                let slack = EDGE_SLACK * (1.0 + p.iter().fold(0f64, |m, v| m.max(v.abs())));
                let inside = (0..3).all(|i| p[i] >= bounds_min[i] - slack && p[i] <= bounds_max[i] + slack);
                (ok(t) && inside).then_some(t)
            }
            Shape::Sphere { center, radius } => {
                let c = [center[0] - o[0], center[1] - o[1], center[2] - o[2]];
                let b = dot(d, c);
                let dd = dot(d, d);
                let disc = b * b - dd * (dot(c, c) - radius * radius);
                if disc < 0.0 {
                    return None;
                }
                let s = disc.sqrt();
                [(b - s) / dd, (b + s) / dd].into_iter().find(|t| ok(*t))
            }
            Shape::Cuboid { min, max } => {
                let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
                for i in 0..3 {
                    if d[i] == 0.0 {
                        if o[i] <= min[i] || o[i] >= max[i] {
                            return None;
                        }
                        continue;
                    }
                    let (a, b) = ((min[i] - o[i]) / d[i], (max[i] - o[i]) / d[i]);
                    t0 = t0.max(a.min(b));
                    t1 = t1.min(a.max(b));
                }
                if t0 > t1 {
                    return None;
                }
                [t0, t1].into_iter().find(|t| ok(*t))
            }
        }
    }
}

impl Scene {
    /// The nearest hit of the ray origin + t dir, t > 0, if any.
    pub fn trace(&self, origin: [f64; 3], dir: [f64; 3]) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for obj in &self.objects {
            if let Some(t) = obj.shape.intersect(origin, dir) {
                if best.is_none_or(|b| t < b.t) {
                    let p = [origin[0] + dir[0] * t, origin[1] + dir[1] * t, origin[2] + dir[2] * t];
                    best = Some(Hit {
                        t,
                        material: obj.pattern,
                        p,
                    });
                }
            }
        }
        best
    }

    /// 1..=[`MAX_OBJECTS`] objects, finite coordinates, positive sizes, known patterns.
    pub fn validate(&self) -> Result<()> {
        if self.objects.is_empty() || self.objects.len() > MAX_OBJECTS {
            return Err(Error::param(
                "scene objects",
                format!("{} outside 1..={MAX_OBJECTS}", self.objects.len()),
            ));
        }
        for (i, o) in self.objects.iter().enumerate() {
            let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
            let good = match o.shape {
                Shape::Plane {
                    point,
                    normal,
                    bounds_min,
                    bounds_max,
                } => {
                    finite(&point)
                        && finite(&normal)
                        && dot(normal, normal) > 0.0
                        && finite(&bounds_min)
                        && finite(&bounds_max)
                }
                Shape::Sphere { center, radius } => finite(&center) && radius.is_finite() && radius > 0.0,
                Shape::Cuboid { min, max } => finite(&min) && finite(&max) && (0..3).all(|k| min[k] < max[k]),
            };
            if !good || o.pattern > 3 {
                return Err(Error::param(
                    format!("scene object {i}"),
                    format!("{o:?}: non-finite, degenerate or pattern > 3"),
                ));
            }
        }
        Ok(())
    }

    /// A scene from a JSON file (`{"name": .., "objects": [{"shape": {"type": "sphere", ..}, "pattern": 2}]}`).
    pub fn load(path: &std::path::Path) -> Result<Scene> {
        let scene: Scene = crate::io::load_json(path, crate::io::MAX_JSON_MAGNITUDE)?;
        scene.validate().map_err(|e| Error::decode(path, e.to_string()))?;
        Ok(scene)
    }
}

const UNBOUNDED: f64 = 1e30;

/// The demo scene: a textured back wall at z = 6, a floor at y = 1.2, a sphere and a tilted plate
/// in front (world = the demo camera's OpenCV frame: x right, y down, z forward).
pub fn demo_scene() -> Scene {
    let plane = |point, normal, bounds_min, bounds_max, pattern| Object {
        shape: Shape::Plane {
            point,
            normal,
            bounds_min,
            bounds_max,
        },
        pattern,
    };
    Scene {
        name: "demo".into(),
        objects: vec![
            plane(
                [0.0, 0.0, 6.0],
                [0.0, 0.0, 1.0],
                [-5.0, -3.5, -UNBOUNDED],
                [5.0, 1.2, UNBOUNDED],
                0,
            ),
            plane(
                [0.0, 1.2, 0.0],
                [0.0, 1.0, 0.0],
                [-5.0, -UNBOUNDED, 0.5],
                [5.0, UNBOUNDED, 6.0],
                1,
            ),
            Object {
                shape: Shape::Sphere {
                    center: [0.6, 0.2, 3.2],
                    radius: 0.7,
                },
                pattern: 2,
            },
            plane(
                [-0.9, -0.1, 2.2],
                [0.35, 0.0, -1.0],
                [-1.4, -0.7, -UNBOUNDED],
                [-0.4, 0.5, UNBOUNDED],
                3,
            ),
        ],
    }
}

/// A second built-in scene: boxes on a floor in front of a wall, for occlusion-heavy views.
pub fn boxes_scene() -> Scene {
    let mut s = demo_scene();
    s.name = "boxes".into();
    s.objects.truncate(2);
    s.objects.push(Object {
        shape: Shape::Cuboid {
            min: [-1.2, 0.2, 2.5],
            max: [-0.4, 1.2, 3.3],
        },
        pattern: 3,
    });
    s.objects.push(Object {
        shape: Shape::Cuboid {
            min: [0.3, -0.4, 3.6],
            max: [1.3, 1.2, 4.4],
        },
        pattern: 2,
    });
    s.objects.push(Object {
        shape: Shape::Sphere {
            center: [-0.2, -0.6, 4.6],
            radius: 0.45,
        },
        pattern: 2,
    });
    s
}

/// Built-in scenes by name.
pub fn builtin(name: &str) -> Result<Scene> {
    match name {
        "demo" => Ok(demo_scene()),
        "boxes" => Ok(boxes_scene()),
        _ => Err(Error::param(
            "scene",
            format!("'{name}': built-in scenes are demo, boxes"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_intersect_where_expected() {
        let s = Shape::Sphere {
            center: [0.0, 0.0, 5.0],
            radius: 1.0,
        };
        assert_eq!(s.intersect([0.0; 3], [0.0, 0.0, 1.0]), Some(4.0));
        assert_eq!(s.intersect([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]), Some(1.0)); // from inside
        let b = Shape::Cuboid {
            min: [-1.0, -1.0, 2.0],
            max: [1.0, 1.0, 3.0],
        };
        assert_eq!(b.intersect([0.0; 3], [0.0, 0.0, 1.0]), Some(2.0));
        assert_eq!(b.intersect([0.0; 3], [0.0, 1.0, 0.0]), None);
        assert!(builtin("demo").unwrap().validate().is_ok() && builtin("boxes").unwrap().validate().is_ok());
        assert!(builtin("nope").is_err());
    }

    #[test]
    fn json_round_trip_and_validation() {
        let text = serde_json::to_string(&boxes_scene()).unwrap();
        let back: Scene = serde_json::from_str(&text).unwrap();
        assert_eq!(back, boxes_scene());
        let mut bad = demo_scene();
        bad.objects[2] = Object {
            shape: Shape::Sphere {
                center: [0.0; 3],
                radius: -1.0,
            },
            pattern: 0,
        };
        assert!(bad.validate().unwrap_err().to_string().contains("scene object 2"));
    }
}
