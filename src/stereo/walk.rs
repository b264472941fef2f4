//! The walks of the 2-D passes ([`super::densify`], [`super::fill`]): from a pixel, along each
//! of 16 directions with integer steps (shaders/cyclopean/directions.glsl holds the same table),
//! to the first pixel that qualifies. Integer steps make the GPU and the twin visit the same
//! texels; 16 directions, rather than the row alone, are what keeps a filled region free of
//! row streaks.

/// The 16 directions, counter-clockwise from +x (rows top-down, so +y is down).
pub const DIRECTIONS: [(i64, i64); 16] = [
    (1, 0),
    (2, 1),
    (1, 1),
    (1, 2),
    (0, 1),
    (-1, 2),
    (-1, 1),
    (-2, 1),
    (-1, 0),
    (-2, -1),
    (-1, -1),
    (-1, -2),
    (0, -1),
    (1, -2),
    (1, -1),
    (2, -1),
];

/// The first pixel from (x, y) along direction `d` for which `hit` holds, no farther than
/// `radius` (Chebyshev distance) and inside `width` x `height`: its position and distance.
pub fn first_along(
    (x, y): (i64, i64),
    (dx, dy): (i64, i64),
    (width, height): (i64, i64),
    radius: i64,
    mut hit: impl FnMut(i64, i64) -> bool,
) -> Option<((i64, i64), i64)> {
    let m = dx.abs().max(dy.abs());
    let mut k = 1;
    while k * m <= radius {
        let (cx, cy) = (x + k * dx, y + k * dy);
        if cx < 0 || cy < 0 || cx >= width || cy >= height {
            return None;
        }
        if hit(cx, cy) {
            return Some(((cx, cy), k * m));
        }
        k += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    /// The GLSL table is this one, in this order.
    #[test]
    fn the_shader_table_is_the_twins() {
        let glsl = include_str!("../../shaders/cyclopean/directions.glsl");
        let table: String = glsl
            .split("ivec2[16](")
            .nth(1)
            .unwrap()
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect();
        let want: String = super::DIRECTIONS
            .iter()
            .map(|(x, y)| format!("ivec2({x},{y})"))
            .collect::<Vec<_>>()
            .join(",");
        assert!(table.starts_with(&want), "directions.glsl: {table}");
    }

    #[test]
    fn a_walk_stops_at_the_first_hit_the_edge_or_the_radius() {
        let size = (10, 10);
        assert_eq!(
            super::first_along((2, 2), (2, 1), size, 9, |x, _| x >= 6),
            Some(((6, 4), 4))
        );
        assert_eq!(super::first_along((2, 2), (-1, 0), size, 9, |_, _| false), None);
        assert_eq!(super::first_along((0, 0), (1, 1), size, 3, |x, _| x == 4), None);
    }
}
