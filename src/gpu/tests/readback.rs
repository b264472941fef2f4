//! The streaming readback of `gpu`: layouts (RGB packed out of RGBA8, f32, bytes), the GPU row
//! flip, targets in flight, and no GL allocation in the steady state. Exact oracles: the bytes
//! uploaded are the bytes expected.

use super::gpu;
use crate::camera::PinholeCamera;
use crate::convention::{Conventions, RowOrder};
use crate::gpu::{Attachment, Framebuffer, ReadFormat, TextureFormat};
use crate::refocus::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use crate::world;

fn attachment(format: TextureFormat) -> Option<Attachment> {
    Some(Attachment {
        format,
        clear: [0.0; 4],
    })
}

#[test]
fn layouts_and_row_flip_match_the_uploaded_bytes() {
    let g = gpu();
    let (w, h) = (7u32, 5u32); // odd sizes: no row padding may creep in
    let fb = Framebuffer::new(
        &g,
        w,
        h,
        &[
            attachment(TextureFormat::Rgba8),
            attachment(TextureFormat::R32F),
            attachment(TextureFormat::R8),
        ],
        false,
    )
    .unwrap();
    let n = (w * h) as usize;
    let rgba: Vec<u8> = (0..n * 4).map(|i| (i * 7 % 251) as u8).collect();
    let depth: Vec<f32> = (0..n).map(|i| i as f32 * 0.37 - 3.0).collect();
    let bytes: Vec<u8> = (0..n).map(|i| (i * 13 % 256) as u8).collect();
    fb.color(0).unwrap().upload(&rgba).unwrap();
    fb.color(1).unwrap().upload(bytemuck::cast_slice(&depth)).unwrap();
    fb.color(2).unwrap().upload(&bytes).unwrap();
    let rgb: Vec<u8> = rgba.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
    let flip = |v: &[u8], row: usize| -> Vec<u8> { v.chunks(row).rev().flatten().copied().collect() };
    // Both flip paths: the GPU blit (what NVIDIA uses) and GL_MESA_pack_invert where Mesa has it.
    for (flipped, pack_invert) in [(false, false), (true, false), (true, true)] {
        g.use_pack_invert(pack_invert);
        // All three queued before any is waited for: several reads in flight.
        let a = fb.read_async(0, ReadFormat::RGB8, flipped).unwrap().unwrap();
        let b = fb.read_async(1, ReadFormat::R32F, flipped).unwrap().unwrap();
        let c = fb.read_async(2, ReadFormat::R8, flipped).unwrap().unwrap();
        let (got_rgb, got_z, got_b) = (a.finish().unwrap(), b.finish_f32().unwrap(), c.finish().unwrap());
        let want_z: Vec<f32> = if flipped {
            depth.chunks(w as usize).rev().flatten().copied().collect()
        } else {
            depth.clone()
        };
        if flipped {
            assert_eq!(got_rgb, flip(&rgb, 3 * w as usize));
            assert_eq!(got_b, flip(&bytes, w as usize));
        } else {
            assert_eq!(got_rgb, rgb);
            assert_eq!(got_b, bytes);
        }
        assert_eq!(got_z, want_z, "f32 readback must be bit-exact (flipped {flipped})");
    }
    g.use_pack_invert(true);
    // The synchronous helper goes through the same path.
    assert_eq!(fb.read_color(0).unwrap().unwrap(), rgba);
}

#[test]
fn steady_state_refocus_allocates_no_readback_buffers() {
    let g = gpu();
    let cam = world::demo_camera(64, 48);
    let (rgb, depth) = world::render(&cam);
    let src = RefocusSource::new(rgb, depth, cam.k).unwrap();
    let conv = Conventions {
        row_order: RowOrder::BottomUp,
        ..Default::default()
    };
    let mut r = Refocuser::new(
        &g,
        &src,
        &BreakRule::default(),
        Method::Fullscreen,
        OutputSet::default(),
        conv,
    )
    .unwrap();
    let targets: Vec<PinholeCamera> = [0.5, 1.0, 2.0]
        .iter()
        .map(|&s| PinholeCamera {
            k: crate::camera::Intrinsics {
                fx: cam.k.fx * s,
                fy: cam.k.fy * s,
                ..cam.k
            },
            ..cam
        })
        .collect();
    // Warm-up: two frames of three targets in flight, as the batch keeps them.
    let mut first = Vec::new();
    for _ in 0..2 {
        r.set_source(&src).unwrap();
        let pending: Vec<_> = targets.iter().map(|t| r.submit(t).unwrap()).collect();
        first = pending.into_iter().map(|p| p.wait().unwrap()).collect();
    }
    let created = g.readback_buffers_created();
    for _ in 0..5 {
        r.set_source(&src).unwrap();
        let pending: Vec<_> = targets.iter().map(|t| r.submit(t).unwrap()).collect();
        for (p, f) in pending.into_iter().zip(&first) {
            let o = p.wait().unwrap();
            assert_eq!(o.rgb.as_ref().unwrap().data, f.rgb.as_ref().unwrap().data);
            assert_eq!(o.mask.as_ref().unwrap().data, f.mask.as_ref().unwrap().data);
        }
    }
    assert_eq!(
        g.readback_buffers_created(),
        created,
        "steady-state frames must reuse pooled pixel-pack buffers"
    );
    // The mask arrives as 0/1 bytes straight from the GPU.
    assert!(first[1].mask.as_ref().unwrap().data.iter().all(|&m| m <= 1));
}
