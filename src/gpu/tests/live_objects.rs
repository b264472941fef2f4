//! The per-context census of live GL objects (`Gpu::live_objects`): each RAII type counts while
//! it lives, and a second identical frame (refocus, cyclopean) leaves the counts where the first
//! left them: no GL object leaks per frame. Exact oracles: the objects this test makes.

use super::{gpu, synthetic};
use crate::camera::PinholeCamera;
use crate::convention::Conventions;
use crate::cyclopean::splat::{SplatParams, SplatRenderer};
use crate::gpu::{Attachment, Framebuffer, Gpu, IndexBuffer, LiveObjects, TextureFormat, VertexArray};
use crate::refocus::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use crate::stereo::gather::CyclopeanOutputs;
use crate::stereo::scene_frame::{scene_frame, StereoRig};
use crate::stereo::FrameDepth;

#[test]
fn each_object_is_counted_while_it_lives() {
    let g = gpu();
    let before = g.live_objects();
    let colour = Some(Attachment {
        format: TextureFormat::Rgba8,
        clear: [0.0; 4],
    });
    let fb = Framebuffer::new(&g, 8, 6, &[colour, None, colour], true).unwrap();
    let vao = VertexArray::new(&g).unwrap();
    let ib = IndexBuffer::new(&g, &[0, 1, 2]).unwrap();
    let live = g.live_objects();
    // Two colour attachments and the depth attachment are textures; None makes none.
    let expected = LiveObjects {
        textures: before.textures + 3,
        framebuffers: before.framebuffers + 1,
        buffers: before.buffers + 1,
        vertex_arrays: before.vertex_arrays + 1,
        ..before
    };
    assert_eq!(live, expected);
    assert_eq!(live.total(), before.total() + 6);
    // A queued read holds a fence (and a pooled pixel-pack buffer) until finished.
    let pending = fb.read_async(0, crate::gpu::ReadFormat::RGB8, false).unwrap().unwrap();
    assert_eq!(g.live_objects().syncs, before.syncs + 1);
    pending.finish().unwrap();
    assert_eq!(g.live_objects().syncs, before.syncs);
    drop((fb, vao, ib));
    let after = g.live_objects();
    // The readback buffer stays pooled for the next read of that size; all else is freed.
    assert_eq!(
        after,
        LiveObjects {
            buffers: before.buffers + 1,
            ..before
        }
    );
}

/// One refocus call as the Python package makes it: a Refocuser for the source, every target
/// rendered and read back, everything dropped.
fn refocus_call(g: &Gpu, src: &RefocusSource, targets: &[PinholeCamera]) -> Vec<Vec<u8>> {
    let mut r = Refocuser::new(
        g,
        src,
        &BreakRule::default(),
        Method::Fullscreen,
        OutputSet::default(),
        Conventions::default(),
    )
    .unwrap();
    assert!(
        g.live_objects().textures > 0,
        "the source is uploaded while the call runs"
    );
    targets.iter().map(|t| r.render(t).unwrap().rgb.unwrap().data).collect()
}

#[test]
fn a_second_identical_refocus_frame_allocates_no_gl_objects() {
    let g = gpu();
    let src = synthetic(48, 36);
    let cam = src.camera();
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
    let first = refocus_call(&g, &src, &targets);
    let warm = g.live_objects();
    // What stays after a call is the readback pool only (one buffer per read size at least).
    assert!(warm.buffers > 0, "{warm:?}");
    assert_eq!(
        (warm.textures, warm.framebuffers, warm.programs, warm.syncs),
        (0, 0, 0, 0),
        "{warm:?}"
    );
    for _ in 0..3 {
        assert_eq!(refocus_call(&g, &src, &targets), first);
        assert_eq!(g.live_objects(), warm);
    }

    // The batch's way: one Refocuser, the source replaced per frame.
    let mut r = Refocuser::new(
        &g,
        &src,
        &BreakRule::default(),
        Method::Fullscreen,
        OutputSet::default(),
        Conventions::default(),
    )
    .unwrap();
    r.set_source(&src).unwrap();
    for t in &targets {
        r.render(t).unwrap();
    }
    let steady = g.live_objects();
    for _ in 0..3 {
        r.set_source(&src).unwrap();
        for t in &targets {
            r.render(t).unwrap();
        }
        assert_eq!(g.live_objects(), steady);
    }
    drop(r);
    assert_eq!(g.live_objects(), warm);
}

#[test]
fn a_second_identical_cyclopean_frame_allocates_no_gl_objects() {
    let g = gpu();
    let (frame, mid, _) = scene_frame(&StereoRig::demo(40, 30), Conventions::default(), FrameDepth::ViewZ);
    let call = || {
        let mut r = SplatRenderer::new(&g, &frame, SplatParams::default(), CyclopeanOutputs::default()).unwrap();
        r.render(&mid).unwrap().0.sources
    };
    let first = call();
    let warm = g.live_objects();
    assert_eq!((warm.textures, warm.framebuffers, warm.programs), (0, 0, 0), "{warm:?}");
    for _ in 0..3 {
        assert_eq!(call(), first);
        assert_eq!(g.live_objects(), warm);
    }
}

/// A sequence's renderer takes the next frame's eyes in place (`SplatRenderer::set_frame`): the
/// view is byte for byte a new renderer's of that frame, and no GL object is made or left.
#[test]
fn a_sequence_frame_rewrites_the_splat_renderer_in_place() {
    let g = gpu();
    let conv = Conventions::all()[6];
    let frame_at = |x: f64| {
        let mut rig = StereoRig::demo(40, 30);
        rig.head.position[0] += x;
        scene_frame(&rig, conv, FrameDepth::Device)
    };
    let (a, _, _) = frame_at(0.0);
    let (b, mid_b, _) = frame_at(0.04);
    let fresh = SplatRenderer::new(&g, &b, SplatParams::default(), CyclopeanOutputs::default())
        .unwrap()
        .render(&mid_b)
        .unwrap()
        .0;
    let mut r = SplatRenderer::new(&g, &a, SplatParams::default(), CyclopeanOutputs::default()).unwrap();
    drop(r.render(&mid_b).unwrap());
    let warm = g.live_objects();
    r.set_frame(&b).unwrap();
    let next = r.render(&mid_b).unwrap().0;
    assert_eq!(g.live_objects(), warm, "set_frame made GL objects");
    assert_eq!(next.sources, fresh.sources);
    assert_eq!(next.color, fresh.color);
    assert_eq!(next.depth, fresh.depth);
    // Another frame's conventions are refused by name: the programs were built for these.
    let (other, _, _) = scene_frame(&StereoRig::demo(40, 30), Conventions::all()[1], FrameDepth::Device);
    let err = r.set_frame(&other).unwrap_err().to_string();
    assert!(err.contains("conventions"), "{err}");
    // A frame the device cannot hold fails set_frame; the renderer then refuses to render
    // (an error, not a panic, nor the last frame's eyes) until it is given a frame again.
    let side = crate::pass::Device::gl(&g).unwrap().max_image_side() + 1;
    let (huge, _, _) = scene_frame(&StereoRig::demo(side, 1), conv, FrameDepth::Device);
    assert!(r.set_frame(&huge).is_err());
    let Err(err) = r.render(&mid_b) else {
        panic!("a renderer without eyes rendered")
    };
    assert!(err.to_string().contains("set_frame"), "{err}");
    r.set_frame(&b).unwrap();
    assert_eq!(r.render(&mid_b).unwrap().0.color, fresh.color);
}

/// `Device::put_image`: an image of the held one's size and format is rewritten in place (same
/// id, no texture made); another shape frees the old before uploading (one texture held); a
/// refused upload leaves the slot empty, so the next call uploads anew.
#[test]
fn put_image_rewrites_in_place_and_replaces_on_a_new_shape() {
    use crate::pass::{Device, Format, ImageData};
    let g = gpu();
    let d = Device::gl(&g).unwrap();
    let data = |width, height, format, bytes| ImageData {
        width,
        height,
        format,
        bytes,
        label: "put_image test",
    };
    let before = g.live_objects().textures;
    let mut slot = None;
    let a = d.put_image(&mut slot, &data(4, 2, Format::R32F, &[0u8; 32])).unwrap();
    assert_eq!(g.live_objects().textures, before + 1);
    let b = d.put_image(&mut slot, &data(4, 2, Format::R32F, &[7u8; 32])).unwrap();
    assert_eq!((a, g.live_objects().textures), (b, before + 1), "same shape: rewritten");
    d.put_image(&mut slot, &data(2, 2, Format::R32F, &[0u8; 16])).unwrap();
    assert_eq!(g.live_objects().textures, before + 1, "new size: the old one freed");
    d.put_image(&mut slot, &data(2, 2, Format::Rgba8, &[0u8; 16])).unwrap();
    assert_eq!(g.live_objects().textures, before + 1, "new format: the old one freed");
    assert!(d.put_image(&mut slot, &data(2, 2, Format::Rgba8, &[0u8; 3])).is_err());
    assert!(slot.is_none(), "a failed write empties the slot");
    assert_eq!(g.live_objects().textures, before);
    d.put_image(&mut slot, &data(2, 2, Format::Rgba8, &[0u8; 16])).unwrap();
    assert_eq!(g.live_objects().textures, before + 1);
}
