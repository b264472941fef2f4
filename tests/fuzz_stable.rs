//! Fuzzing on stable Rust: every target of `fuzz/` (bodies in fuzz/fuzz_targets/bodies.rs, the
//! same code the cargo-fuzz binaries run on nightly) gets
//! 1. its checked-in corpus `fuzz/corpus/<target>/` and regressions `fuzz/regressions/<target>/`
//!    replayed, then
//! 2. a time-boxed random-mutation loop over that corpus (bit flips, interesting bytes and
//!    integers, inserts, deletes, duplications, splices, truncations), deterministic for a seed.
//!
//! Budget: `VIEWSYNTH_FUZZ_SECS` seconds per target (default 1, what `cargo test` spends;
//! `.ci/run` runs this test again with 30), seed `VIEWSYNTH_FUZZ_SEED` (default: fixed, so a
//! plain `cargo test` is reproducible). A panic is a finding: the input is written to
//! `target/fuzz-findings/<target>/<hash>` and the test fails naming it; copy it into
//! `fuzz/regressions/<target>/` with the fix, and it is replayed from then on.

#[path = "../fuzz/fuzz_targets/bodies.rs"]
mod bodies;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A run longer than this on one input is reported as a hang (inputs are a few KB).
const SLOW: Duration = Duration::from_secs(5);
/// Mutated inputs are capped (the loaders' limits are tested elsewhere).
const MAX_LEN: usize = 64 * 1024;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn inputs_in(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.path().is_file())
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// xorshift64*: small, deterministic, good enough to pick mutations.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const INTERESTING_U8: [u8; 9] = [0, 1, 0x7f, 0x80, 0xff, b'\n', b',', b'"', b'{'];
const INTERESTING_U32: [u32; 8] = [0, 1, 0x7fff, 0xffff, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, 16385];

fn mutate(rng: &mut Rng, input: &[u8], corpus: &[(String, Vec<u8>)]) -> Vec<u8> {
    let mut v = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let n = v.len();
        match rng.below(9) {
            0 if n > 0 => {
                let i = rng.below(n);
                v[i] ^= 1 << rng.below(8);
            }
            1 if n > 0 => {
                let i = rng.below(n);
                v[i] = INTERESTING_U8[rng.below(INTERESTING_U8.len())];
            }
            2 if n >= 4 => {
                let i = rng.below(n - 3);
                let x = INTERESTING_U32[rng.below(INTERESTING_U32.len())];
                let bytes = if rng.below(2) == 0 {
                    x.to_le_bytes()
                } else {
                    x.to_be_bytes()
                };
                v[i..i + 4].copy_from_slice(&bytes);
            }
            3 => {
                let i = rng.below(n + 1);
                let k = 1 + rng.below(16);
                let fill: Vec<u8> = (0..k).map(|_| rng.next() as u8).collect();
                v.splice(i..i, fill);
            }
            4 if n > 0 => {
                let i = rng.below(n);
                let k = 1 + rng.below((n - i).min(64));
                v.drain(i..i + k);
            }
            5 if n > 0 => {
                let i = rng.below(n);
                let k = 1 + rng.below((n - i).min(64));
                let chunk = v[i..i + k].to_vec();
                let at = rng.below(n + 1);
                v.splice(at..at, chunk);
            }
            6 if !corpus.is_empty() => {
                let other = &corpus[rng.below(corpus.len())].1;
                let cut = rng.below(v.len() + 1);
                let from = rng.below(other.len() + 1);
                v.truncate(cut);
                v.extend_from_slice(&other[from..]);
            }
            7 if n > 0 => v.truncate(rng.below(n)),
            _ if n > 1 => {
                // Keep the selector byte, scramble one other.
                let i = 1 + rng.below(n - 1);
                v[i] = rng.next() as u8;
            }
            _ => v.push(rng.next() as u8),
        }
    }
    v.truncate(MAX_LEN);
    v
}

/// Runs `body` on `data`; a panic or a hang is a finding, saved under target/.
fn run_one(name: &str, body: fn(&[u8]), data: &[u8], findings: &mut Vec<String>) {
    let t0 = Instant::now();
    let result = catch_unwind(AssertUnwindSafe(|| body(data)));
    let slow = t0.elapsed() > SLOW;
    if result.is_err() || slow {
        let mut h = flate2::Crc::new();
        h.update(data);
        let dir = root().join("target/fuzz-findings").join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("{:08x}", h.sum()));
        std::fs::write(&path, data).unwrap();
        let what = if slow {
            format!("hang ({:?})", t0.elapsed())
        } else {
            "panic".into()
        };
        findings.push(format!("{name}: {what} on {} ({} bytes)", path.display(), data.len()));
    }
}

fn fuzz(name: &str, body: fn(&[u8])) {
    let corpus = inputs_in(&root().join("fuzz/corpus").join(name));
    let regressions = inputs_in(&root().join("fuzz/regressions").join(name));
    assert!(
        corpus.len() >= 3,
        "{name}: the checked-in corpus is missing (fuzz/corpus/{name})"
    );
    let mut findings = Vec::new();
    // Quiet panics while fuzzing: findings are listed at the end.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    for (_, data) in corpus.iter().chain(&regressions) {
        run_one(name, body, data, &mut findings);
    }
    let secs: f64 = std::env::var("VIEWSYNTH_FUZZ_SECS")
        .ok()
        .map_or(1.0, |s| s.parse().expect("VIEWSYNTH_FUZZ_SECS"));
    let seed: u64 = std::env::var("VIEWSYNTH_FUZZ_SEED")
        .ok()
        .map_or(0x5EED_0027, |s| s.parse().expect("VIEWSYNTH_FUZZ_SEED"));
    let mut rng = Rng(seed
        ^ name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
        }));
    let deadline = Instant::now() + Duration::from_secs_f64(secs);
    let mut runs = 0usize;
    while Instant::now() < deadline && findings.len() < 10 {
        let base = &corpus[rng.below(corpus.len())].1;
        let input = mutate(&mut rng, base, &corpus);
        run_one(name, body, &input, &mut findings);
        runs += 1;
    }
    std::panic::set_hook(hook);
    eprintln!(
        "{name}: {} corpus + {} regression inputs, {runs} mutations in {secs} s",
        corpus.len(),
        regressions.len()
    );
    assert!(
        findings.is_empty(),
        "{} finding(s):\n{}",
        findings.len(),
        findings.join("\n")
    );
    assert!(runs > 0, "{name}: no mutation ran");
}

#[test]
fn fuzz_load_depth() {
    fuzz(bodies::TARGETS[0].0, bodies::TARGETS[0].1);
}

#[test]
fn fuzz_load_rgb() {
    fuzz(bodies::TARGETS[1].0, bodies::TARGETS[1].1);
}

#[test]
fn fuzz_json_inputs() {
    fuzz(bodies::TARGETS[2].0, bodies::TARGETS[2].1);
}

#[test]
fn fuzz_batch_manifest() {
    fuzz(bodies::TARGETS[3].0, bodies::TARGETS[3].1);
}

#[test]
fn fuzz_npz() {
    fuzz(bodies::TARGETS[4].0, bodies::TARGETS[4].1);
}

/// Writes the seed corpus (`fuzz/corpus/<target>/`) from the library's own writers and small
/// hand-made files. Run by hand after a format change; the files are checked in.
#[test]
#[ignore = "regenerates the checked-in seed corpus fuzz/corpus; run by hand after a format change"]
fn write_seed_corpus() {
    use viewsynth::io::{self, DepthMap, PngCompression, RgbImage};
    let tmp = tempfile::tempdir().unwrap();
    let file = |name: &str| tmp.path().join(name);
    let read = |p: PathBuf| std::fs::read(p).unwrap();
    let seed = |target: &str, name: &str, bytes: Vec<u8>| {
        let dir = root().join("fuzz/corpus").join(target);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(name), bytes).unwrap();
    };
    let (w, h) = (5u32, 3u32);
    let depth = DepthMap::new(
        w,
        h,
        (0..w * h)
            .map(|i| if i == 4 { 0.0 } else { 0.5 + 0.25 * i as f32 })
            .collect(),
    )
    .unwrap();
    let rgb = RgbImage::new(w, h, (0..w * h * 3).map(|i| (i * 17 % 256) as u8).collect()).unwrap();
    let with = |sel: u8, mut b: Vec<u8>| {
        b.insert(0, sel);
        b
    };
    // load_depth: the first byte picks npy 0, exr 1, png 2, pgm 3, pfm 4 (+8: scale 1000).
    io::save_depth_npy(&file("d.npy"), &depth).unwrap();
    seed("load_depth", "npy", with(0, read(file("d.npy"))));
    io::save_depth_exr(&file("d.exr"), &depth).unwrap();
    seed("load_depth", "exr", with(1, read(file("d.exr"))));
    io::save_depth_png16(&file("d.png"), &depth, io::Png16Units::default(), PngCompression::Fast).unwrap();
    seed("load_depth", "png16", with(2 | 8, read(file("d.png"))));
    let mut pgm = format!("P5\n{w} {h}\n65535\n").into_bytes();
    pgm.extend(depth.data.iter().flat_map(|z| ((z * 1000.0) as u16).to_be_bytes()));
    seed("load_depth", "pgm16", with(3 | 8, pgm));
    let mut pfm = format!("Pf\n{w} {h}\n-1.0\n").into_bytes();
    pfm.extend(depth.data.iter().flat_map(|z| z.to_le_bytes()));
    seed("load_depth", "pfm", with(4, pfm));
    // load_rgb: PNG, JPEG, PPM; a mask PNG.
    io::save_rgb(&file("c.png"), &rgb).unwrap();
    seed("load_rgb", "png", read(file("c.png")));
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new(&mut jpeg)
        .encode(&rgb.data, w, h, image::ExtendedColorType::Rgb8)
        .unwrap();
    seed("load_rgb", "jpeg", jpeg);
    let mut ppm = format!("P6\n{w} {h}\n255\n").into_bytes();
    ppm.extend_from_slice(&rgb.data);
    seed("load_rgb", "ppm", ppm);
    io::save_mask_png(
        &file("m.png"),
        &io::Mask {
            width: w,
            height: h,
            data: (0..w * h).map(|i| (i % 2) as u8).collect(),
        },
    )
    .unwrap();
    seed("load_rgb", "mask", read(file("m.png")));
    // json_inputs: the camera file `scene` writes, a cyclopean camera file, an empty object.
    struct Quiet;
    impl viewsynth::job::Host for Quiet {
        fn open_gpu(&self, request: &viewsynth::job::GpuRequest) -> viewsynth::Result<viewsynth::gpu::Gpu> {
            request.open()
        }
        fn event(&self, _: viewsynth::job::Event<'_>) {}
    }
    let scene = viewsynth::job::scene::SceneJob::new(viewsynth::job::scene::SceneOptions {
        scene: "demo".into(),
        width: 16,
        height: 12,
        ipd: 0.064,
        conventions: Default::default(),
        cube_faces: None,
        face_fov: 110.0,
        frames: 1,
        dolly: 0.02,
        spectator_offset: 0.0,
        out_dir: tmp.path().join("scene"),
        gpu: viewsynth::job::GpuRequest::new("auto", false).unwrap(),
        backend: viewsynth::job::Backend::Gl,
    })
    .unwrap();
    scene.run(&Quiet).unwrap();
    seed(
        "json_inputs",
        "scene_cameras",
        read(tmp.path().join("scene/cameras.json")),
    );
    seed("json_inputs", "empty", b"{}".to_vec());
    seed("json_inputs", "array", b"[1, 2.5e300, null, \"x\"]".to_vec());
    // batch_manifest: first byte even = CSV, odd = JSON.
    seed("batch_manifest", "csv", with(0, b"rgb,depth,fx,fy,cx,cy,depth_scale,name\n# a comment\nc.png,d.png,40,40,15.5,11.5,1000,f0\n\"a,b.png\",d.npy,40,41,15,11,,f1\n".to_vec()));
    seed(
        "batch_manifest",
        "json",
        with(
            1,
            br#"[{"rgb": "c.png", "depth": "d.npy", "fx": 40, "fy": 40, "cx": 15.5, "cy": 11.5, "name": "f0"}]"#
                .to_vec(),
        ),
    );
    seed(
        "batch_manifest",
        "bom",
        with(
            0,
            "\u{feff}rgb,depth,fx,fy,cx,cy\nc.png,d.npy,1,1,0,0\n"
                .as_bytes()
                .to_vec(),
        ),
    );
    // npz: first byte picks the key (none, arr_0, disp); members stored, deflated, zip64, as
    // numpy's zipfile writes them (CRCs, a central directory).
    let npy = read(file("d.npy"));
    let npz = |members: &[(&str, bool)], zip64: bool| -> Vec<u8> {
        use std::io::Write;
        let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        for &(name, deflate) in members {
            let method = if deflate {
                zip::CompressionMethod::Deflated
            } else {
                zip::CompressionMethod::Stored
            };
            let options = zip::write::SimpleFileOptions::default()
                .compression_method(method)
                .large_file(zip64);
            w.start_file(name, options).unwrap();
            w.write_all(&npy).unwrap();
        }
        w.finish().unwrap().into_inner()
    };
    seed("npz", "stored", with(0, npz(&[("arr_0.npy", false)], false)));
    seed("npz", "deflated", with(1, npz(&[("arr_0.npy", true)], false)));
    let two = npz(&[("disp.npy", true), ("arr_0.npy", false)], true);
    seed("npz", "zip64_two_members", with(2, two));
}
