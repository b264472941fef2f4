//! Hostile input against the binary, one case per defect of issue 11 and more: symlinks, FIFOs,
//! devices, empty/huge/truncated files, header bombs, out-of-range numbers, non-UTF-8 paths,
//! concurrent runs on one folder, kill -9 then rerun. Every case asserts the exit status, the
//! message, that nothing outside the out-dir changed and that the out-dir holds no temporary
//! and no file of a failed run. Runs that must refuse before allocating pixels are given an
//! address-space limit far below what decoding the declared image would take, so a refusal
//! that came too late would show as a crash, not pass.

use crate::common::assert_no_failures;
use std::collections::BTreeMap;
use std::ffi::{OsStr, OsString};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::os::unix::fs::{symlink, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use viewsynth::io::{self, DepthMap, RgbImage};

use crate::cli::{bin, files_in, scratch, temporaries};

/// Address-space limit (KiB) for runs that must fail before reading pixels: a 16383 x 16383
/// image would need over 800 MB for its colour alone.
const REFUSAL_ADDRESS_SPACE_KIB: u64 = 400 * 1024;

const W: u32 = 32;
const H: u32 = 24;

/// What a path holds, read without following symlinks (FIFOs and devices are never opened).
#[derive(Debug, PartialEq)]
enum Entry {
    File(Vec<u8>, u32),
    /// Length, modification time and mode of a file too big to compare by content.
    Big(u64, std::time::SystemTime, u32),
    Link(PathBuf),
    Dir,
    Other,
}

fn snapshot(root: &Path, skip: &Path) -> BTreeMap<PathBuf, Entry> {
    let mut map = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let p = e.path();
            if p == skip {
                continue;
            }
            let m = std::fs::symlink_metadata(&p).unwrap();
            let entry = if m.file_type().is_symlink() {
                Entry::Link(std::fs::read_link(&p).unwrap())
            } else if m.is_dir() {
                stack.push(p.clone());
                Entry::Dir
            } else if m.is_file() && m.len() > 1 << 20 {
                Entry::Big(m.len(), m.modified().unwrap(), m.permissions().mode())
            } else if m.is_file() {
                Entry::File(std::fs::read(&p).unwrap(), m.permissions().mode())
            } else {
                Entry::Other
            };
            map.insert(p, entry);
        }
    }
    map
}

/// A sandbox: valid inputs, hostile files, a victim folder, and the out-dir `out/`.
struct Sandbox {
    root: PathBuf,
    out: PathBuf,
}

impl Sandbox {
    fn new(name: &str) -> Self {
        let root = scratch(&format!("hostile-{name}"));
        let out = root.join("out");
        std::fs::create_dir_all(root.join("victim")).unwrap();
        std::fs::write(root.join("victim/precious.txt"), b"must never change").unwrap();
        Self { root, out }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.root.join(name)
    }

    /// Runs `args`, checks the status and message, and that nothing outside `out/` changed
    /// and `out/` is as before (no temporary, no output of the failed run).
    fn refuses(&self, failures: &mut Vec<String>, label: &str, args: &[OsString], code: i32, needles: &[&str]) {
        let before = snapshot(&self.root, &self.out);
        let out_before = snapshot_or_empty(&self.out);
        let o = run_limited(args);
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        let mut problems = Vec::new();
        if o.status.code() != Some(code) {
            problems.push(format!("exit {:?}, expected {code}", o.status.code()));
        }
        for n in needles {
            if !err.contains(n) {
                problems.push(format!("message lacks '{n}'"));
            }
        }
        if err.contains("panicked") {
            problems.push("panicked".into());
        }
        if err.matches("(os error").count() > 1 {
            problems.push("'(os error N)' printed twice".into());
        }
        if snapshot(&self.root, &self.out) != before {
            problems.push("a file outside the out-dir changed".into());
        }
        if snapshot_or_empty(&self.out) != out_before {
            problems.push(format!("out-dir changed: {:?}", files_in(&self.out)));
        }
        if !problems.is_empty() {
            failures.push(format!("{label}: {} -- stderr: {}", problems.join("; "), err.trim()));
        }
    }
}

fn snapshot_or_empty(dir: &Path) -> BTreeMap<PathBuf, Entry> {
    if dir.is_dir() {
        snapshot(dir, Path::new(""))
    } else {
        BTreeMap::new()
    }
}

/// The binary under an address-space limit.
fn run_limited(args: &[OsString]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {REFUSAL_ADDRESS_SPACE_KIB}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_viewsynth"))
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("run viewsynth")
}

fn os(args: &[&str]) -> Vec<OsString> {
    args.iter().map(OsString::from).collect()
}

fn with(mut base: Vec<OsString>, flag: &str, value: &Path) -> Vec<OsString> {
    base.push(flag.into());
    base.push(value.into());
    base
}

fn write_inputs(dir: &Path, w: u32, h: u32, tag: &str) -> (PathBuf, PathBuf) {
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    let depth: Vec<f32> = (0..w * h).map(|i| 1.0 + 0.01 * (i % w) as f32).collect();
    let (rp, dp) = (dir.join(format!("{tag}rgb.png")), dir.join(format!("{tag}depth.npy")));
    io::save_rgb(&rp, &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    io::save_depth_npy(&dp, &DepthMap::new(w, h, depth).unwrap()).unwrap();
    (rp, dp)
}

/// A JPEG whose frame header declares `side x side` (encoded small, then patched).
fn jpeg_declaring(side: u16) -> Vec<u8> {
    let img = image::RgbImage::from_pixel(16, 16, image::Rgb([90, 120, 150]));
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new(&mut bytes)
        .encode_image(&img)
        .unwrap();
    let sof = bytes.windows(2).position(|w| w == [0xFF, 0xC0]).unwrap();
    // FF C0, length (2), precision (1), height (2), width (2).
    bytes[sof + 5..sof + 7].copy_from_slice(&side.to_be_bytes());
    bytes[sof + 7..sof + 9].copy_from_slice(&side.to_be_bytes());
    bytes
}

/// A PNG whose header declares `w x h` RGB with a tiny (incomplete) pixel stream.
fn png_declaring(w: u32, h: u32) -> Vec<u8> {
    fn chunk(out: &mut Vec<u8>, kind: &[u8], data: &[u8]) {
        out.extend((data.len() as u32).to_be_bytes());
        let start = out.len();
        out.extend(kind);
        out.extend(data);
        let crc = crc32(&out[start..]);
        out.extend(crc.to_be_bytes());
    }
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &[0x78, 0x9c, 0x63, 0, 0, 0, 1, 0, 1]);
    chunk(&mut out, b"IEND", &[]);
    out
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

fn npy_header(shape: &str, descr: &str) -> Vec<u8> {
    let mut dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend((dict.len() as u16).to_le_bytes());
    out.extend(dict.as_bytes());
    out
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

/// A hostile file and a text its error must contain.
type Hostile = (PathBuf, &'static str);

/// Hostile colour and depth files in `sb/in/`.
fn hostile_files(sb: &Sandbox) -> (Vec<Hostile>, Vec<Hostile>) {
    let d = sb.path("in");
    std::fs::create_dir_all(&d).unwrap();
    let (rgb, depth) = write_inputs(&d, W, H, "ok_");
    let put = |name: &str, bytes: &[u8]| {
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let png = std::fs::read(&rgb).unwrap();
    let npy = std::fs::read(&depth).unwrap();
    let jpeg = {
        let mut b = Vec::new();
        let img = image::RgbImage::from_fn(W, H, |x, y| image::Rgb([(x * 7) as u8, (y * 9) as u8, 60]));
        image::codecs::jpeg::JpegEncoder::new(&mut b)
            .encode_image(&img)
            .unwrap();
        b
    };
    let exr = d.join("ok_depth.exr");
    io::save_depth_exr(&exr, &io::load_depth(&depth, &Default::default()).unwrap()).unwrap();
    let exr_bytes = std::fs::read(&exr).unwrap();

    let mut colour = Vec::new();
    let mut depths = Vec::new();
    // Shared by both slots.
    for (slot, ext) in [(&mut colour, "png"), (&mut depths, "npy")] {
        slot.push((d.join(format!("missing.{ext}")), "No such file"));
        slot.push((put(&format!("empty.{ext}"), b""), "empty."));
        let fifo = d.join(format!("fifo.{ext}"));
        mkfifo(&fifo);
        slot.push((fifo, "a FIFO"));
        let zero = d.join(format!("zero.{ext}"));
        symlink("/dev/zero", &zero).unwrap();
        slot.push((zero, "a character device"));
        let folder = d.join(format!("folder.{ext}"));
        std::fs::create_dir(&folder).unwrap();
        slot.push((folder, "a directory"));
        let dangling = d.join(format!("dangling.{ext}"));
        symlink(d.join("nowhere"), &dangling).unwrap();
        slot.push((dangling, "No such file"));
    }
    colour.push((put("garbage.png", b"\x89PNG\r\n\x1a\nnot a png at all"), "garbage.png"));
    colour.push((put("text.png", b"hello, this is text"), "unrecognised image format"));
    colour.push((put("trunc.png", &png[..png.len() / 2]), "trunc.png"));
    colour.push((put("trunc.jpg", &jpeg[..jpeg.len() * 2 / 3]), "trunc.jpg"));
    // Cut inside the scan: the decoder alone would fill the rest with grey and succeed.
    colour.push((put("trunc_scan.jpg", &jpeg[..jpeg.len() - 40]), "truncated JPEG"));
    colour.push((put("noeoi.jpg", &jpeg[..jpeg.len() - 2]), "truncated JPEG"));
    colour.push((put("bomb.png", &png_declaring(16383, 16383)), "pixel budget"));
    colour.push((put("bomb_wide.png", &png_declaring(16384 * 4, 2)), "bomb_wide.png"));
    colour.push((put("bomb.jpg", &jpeg_declaring(16383)), "pixel budget"));
    colour.push((put("bomb.ppm", b"P6\n16383 16383\n255\n\x00\x00\x00"), "pixel budget"));
    colour.push((put("trunc.ppm", b"P6\n32 24\n255\n\x00\x00\x00"), "trunc.ppm"));
    let (_, small_depth) = write_inputs(&d, W / 2, H / 2, "small_");
    colour.push((d.join("small_rgb.png"), "size mismatch"));
    depths.push((small_depth, "size mismatch"));
    depths.push((put("trunc.npy", &npy[..npy.len() - 3]), "truncated"));
    let mut trailing = npy.clone();
    trailing.extend([0u8; 8]);
    depths.push((put("trailing.npy", &trailing), "trailing bytes"));
    // A 3 GiB file with a small header: refused from its length, never read (sparse on disk).
    let huge = put("huge.npy", &npy);
    std::fs::OpenOptions::new()
        .write(true)
        .open(&huge)
        .unwrap()
        .set_len(3 << 30)
        .unwrap();
    depths.push((huge, "trailing bytes"));
    let mut bomb = npy_header("(16383, 16383)", "<f4");
    bomb.extend([0u8; 64]);
    depths.push((put("bomb.npy", &bomb), "pixel budget"));
    let mut overflow = npy_header("(18446744073709551615, 2)", "<f4");
    overflow.extend([0u8; 8]);
    depths.push((put("overflow.npy", &overflow), "overflow.npy"));
    depths.push((
        put("hugeheader.npy", b"\x93NUMPY\x02\x00\xff\xff\xff\x7f{"),
        "header length",
    ));
    depths.push((
        put("u8.npy", &{
            let mut b = npy_header("(24, 32)", "|u1");
            b.extend(vec![1u8; (W * H) as usize]);
            b
        }),
        "uint8",
    ));
    depths.push((put("text.npy", b"not numpy"), "NUMPY magic"));
    depths.push((put("bomb.pfm", b"Pf\n16383 16383\n-1.0\n\0\0\0\0"), "pixel budget"));
    depths.push((put("trunc.pfm", b"Pf\n32 24\n-1.0\n\0\0\0\0"), "trunc.pfm"));
    depths.push((put("bomb.pgm", b"P5\n16383 16383\n65535\n\0\0"), "pixel budget"));
    depths.push((put("trunc.pgm", b"P5\n32 24\n65535\n\0\0"), "truncated"));
    depths.push((
        put("plain_huge.pgm", &{
            let mut b = b"P2\n2 1\n255\n".to_vec();
            b.extend(vec![b' '; 2 << 20]);
            b
        }),
        "plain_huge.pgm",
    ));
    depths.push((put("trunc.exr", &exr_bytes[..exr_bytes.len() / 2]), "trunc.exr"));
    depths.push((put("bomb.png", &png_declaring(16383, 16383)), "pixel budget"));
    depths.push((put("unknown.tiff", b"II*\0"), "unknown depth format"));
    let zero_exr = d.join("zero.exr");
    symlink("/dev/zero", &zero_exr).unwrap();
    depths.push((zero_exr, "a character device"));
    let fifo_pfm = d.join("fifo.pfm");
    mkfifo(&fifo_pfm);
    depths.push((fifo_pfm, "a FIFO"));
    (colour, depths)
}

#[test]
fn hostile_inputs_are_refused_before_reading_pixels() {
    let sb = Sandbox::new("inputs");
    let (colour, depths) = hostile_files(&sb);
    let d = sb.path("in");
    let (rgb, depth) = (d.join("ok_rgb.png"), d.join("ok_depth.npy"));
    let out = sb.out.clone();
    let refocus = || {
        let a = os(&["refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"]);
        with(a, "--out-dir", &out)
    };
    let reproject = || {
        let a = os(&[
            "reproject",
            "--fx",
            "40",
            "--fy",
            "40",
            "--cx",
            "15.5",
            "--cy",
            "11.5",
            "--baseline",
            "0.1",
        ]);
        with(a, "--out-dir", &out)
    };
    let mut failures = Vec::new();
    let mut cases = 0;
    for (file, needle) in &colour {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        for (cmd, args) in [
            ("refocus --rgb", with(with(refocus(), "--rgb", file), "--depth", &depth)),
            (
                "reproject --color",
                with(with(reproject(), "--color", file), "--depth", &depth),
            ),
        ] {
            cases += 1;
            sb.refuses(&mut failures, &format!("{cmd} {name}"), &args, 1, &[needle, &name]);
        }
    }
    for (file, needle) in &depths {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        for (cmd, args) in [
            ("refocus --depth", with(with(refocus(), "--rgb", &rgb), "--depth", file)),
            (
                "reproject --depth",
                with(with(reproject(), "--color", &rgb), "--depth", file),
            ),
        ] {
            cases += 1;
            sb.refuses(&mut failures, &format!("{cmd} {name}"), &args, 1, &[needle, &name]);
        }
    }
    // The budget is the user's: a valid pair above a small --max-pixels is refused too.
    let mut args = with(with(refocus(), "--rgb", &rgb), "--depth", &depth);
    args.extend(os(&["--max-pixels", "100"]));
    cases += 1;
    sb.refuses(
        &mut failures,
        "--max-pixels 100",
        &args,
        1,
        &["pixel budget of 100", "32x24"],
    );
    assert!(cases >= 80, "{cases}");
    assert_no_failures(failures, cases);
}

/// A cameras.json for a 32 x 24 stereo pair 64 mm apart (GL matrices, view Z depth).
fn cameras_json(extra_proj_00: &str) -> String {
    let proj = format!("[[{extra_proj_00},0,0,0],[0,3.3,0,0],[0,0,-1.002,-0.2002],[0,0,-1,0]]");
    let view = |x: f64| format!("[[1,0,0,{x}],[0,1,0,0],[0,0,1,0],[0,0,0,1]]");
    format!(
        r#"{{"depth_kind": "view-z",
  "left": {{"view": {}, "proj": {proj}}},
  "right": {{"view": {}, "proj": {proj}}},
  "middle": {{"view": {}, "proj": {proj}, "width": 32, "height": 24}},
  "fixation_distance": 2.0}}"#,
        view(0.032),
        view(-0.032),
        view(0.0)
    )
}

#[test]
fn hostile_cyclopean_stitch_scene_and_json_inputs() {
    let sb = Sandbox::new("json");
    let (colour, depths) = hostile_files(&sb);
    let d = sb.path("in");
    let (rgb, depth) = (d.join("ok_rgb.png"), d.join("ok_depth.npy"));
    let cams = d.join("cameras.json");
    std::fs::write(&cams, cameras_json("2.5")).unwrap();
    let out = sb.out.clone();
    let cyclopean = |lr: &Path, ld: &Path, cams: &Path| {
        let a = with(os(&["cyclopean"]), "--left-rgb", lr);
        let a = with(
            with(with(a, "--left-depth", ld), "--right-rgb", &rgb),
            "--right-depth",
            &depth,
        );
        with(with(a, "--cameras", cams), "--out-dir", &out)
    };
    let mut failures = Vec::new();
    let mut cases = 0;
    for (file, needle) in colour.iter().take(8) {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        cases += 1;
        sb.refuses(
            &mut failures,
            &format!("cyclopean --left-rgb {name}"),
            &cyclopean(file, &depth, &cams),
            1,
            &[needle, &name],
        );
    }
    for (file, needle) in depths.iter().filter(|(p, _)| p.to_string_lossy().contains("bomb")) {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        cases += 1;
        sb.refuses(
            &mut failures,
            &format!("cyclopean --left-depth {name}"),
            &cyclopean(&rgb, file, &cams),
            1,
            &[needle, &name],
        );
    }
    // Camera files: huge, non-finite-by-overflow and non-number values, FIFOs, BOMs, junk.
    let bad_cams: Vec<(&str, Vec<u8>, &str)> = vec![
        ("proj1e308.json", cameras_json("1e308").into_bytes(), "left.proj[0][0]"),
        ("proj1e7.json", cameras_json("1e7").into_bytes(), "magnitude <= 1e6"),
        ("projneg.json", cameras_json("-2e6").into_bytes(), "magnitude <= 1e6"),
        ("overflow.json", cameras_json("1e400").into_bytes(), "overflow.json"),
        ("empty.json", Vec::new(), "empty.json"),
        ("junk.json", b"{\"depth_kind\": ".to_vec(), "junk.json"),
        (
            "unknown_key.json",
            cameras_json("2.5").replacen("{", "{\"bogus\": 1, ", 1).into_bytes(),
            "bogus",
        ),
    ];
    for (name, bytes, needle) in &bad_cams {
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        cases += 1;
        sb.refuses(
            &mut failures,
            &format!("cyclopean --cameras {name}"),
            &cyclopean(&rgb, &depth, &p),
            1,
            &[needle, name],
        );
    }
    let fifo = d.join("fifo.json");
    mkfifo(&fifo);
    cases += 1;
    sb.refuses(
        &mut failures,
        "cyclopean --cameras fifo",
        &cyclopean(&rgb, &depth, &fifo),
        1,
        &["a FIFO"],
    );
    let big = d.join("big.json");
    std::fs::File::create(&big).unwrap().set_len(64 << 20).unwrap();
    cases += 1;
    sb.refuses(
        &mut failures,
        "cyclopean --cameras 64 MiB",
        &cyclopean(&rgb, &depth, &big),
        1,
        &["big.json", "bytes"],
    );

    // Scene files (sphere 1e308), refused before any GPU work.
    for (name, body, needle) in [
        (
            "sphere.json",
            r#"{"name":"s","objects":[{"shape":{"type":"sphere","center":[0,0,3],"radius":1e308},"pattern":1}]}"#,
            "radius",
        ),
        (
            "centre.json",
            r#"{"name":"s","objects":[{"shape":{"type":"sphere","center":[0,0,1e300],"radius":1},"pattern":1}]}"#,
            "center[2]",
        ),
    ] {
        let p = d.join(name);
        std::fs::write(&p, body).unwrap();
        let args = with(
            with(os(&["scene", "--width", "32", "--height", "24"]), "--scene", &p),
            "--out-dir",
            &out,
        );
        cases += 1;
        sb.refuses(
            &mut failures,
            &format!("scene {name}"),
            &args,
            1,
            &[needle, "magnitude"],
        );
    }

    // A stitch face with two depth files: both named, nothing guessed.
    let faces = sb.path("faces");
    std::fs::create_dir_all(&faces).unwrap();
    std::fs::copy(&rgb, faces.join("left_pz.png")).unwrap();
    std::fs::copy(&depth, faces.join("left_pz_depth.npy")).unwrap();
    std::fs::copy(d.join("ok_depth.exr"), faces.join("left_pz_depth.exr")).unwrap();
    let args = with(with(os(&["stitch"]), "--faces", &faces), "--out-dir", &out);
    cases += 1;
    sb.refuses(
        &mut failures,
        "stitch two depth files",
        &args,
        1,
        &["left_pz_depth.exr", "left_pz_depth.npy", "keep one"],
    );
    std::fs::remove_file(faces.join("left_pz_depth.exr")).unwrap();
    std::fs::copy(&rgb, faces.join("left_pz.jpg")).unwrap();
    cases += 1;
    sb.refuses(
        &mut failures,
        "stitch two colour files",
        &args,
        1,
        &["left_pz.png", "left_pz.jpg"],
    );
    assert_no_failures(failures, cases);
}

#[test]
fn numeric_options_are_range_checked_as_usage_errors() {
    let sb = Sandbox::new("options");
    let d = sb.path("in");
    std::fs::create_dir_all(&d).unwrap();
    let (rgb, depth) = write_inputs(&d, W, H, "");
    let manifest = d.join("m.csv");
    std::fs::write(&manifest, "rgb,depth,fx,fy,cx,cy\nrgb.png,depth.npy,40,40,15.5,11.5\n").unwrap();
    let out = sb.out.clone();
    let refocus = |extra: &[&str]| {
        let a = os(&["refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"]);
        let mut a = with(with(with(a, "--rgb", &rgb), "--depth", &depth), "--out-dir", &out);
        a.extend(os(extra));
        a
    };
    // Intrinsics replaced rather than repeated (clap refuses a repeated flag).
    let refocus_k = |k: [&str; 4]| {
        let a = os(&["refocus", "--fx", k[0], "--fy", k[1], "--cx", k[2], "--cy", k[3]]);
        with(with(with(a, "--rgb", &rgb), "--depth", &depth), "--out-dir", &out)
    };
    let batch = |extra: &[&str]| {
        let mut a = with(with(os(&["refocus"]), "--batch", &manifest), "--out-dir", &out);
        a.extend(os(extra));
        a
    };
    let reproject = |extra: &[&str]| {
        let a = os(&[
            "reproject",
            "--fx",
            "40",
            "--fy",
            "40",
            "--cx",
            "15.5",
            "--cy",
            "11.5",
            "--baseline",
            "0.1",
        ]);
        let mut a = with(with(with(a, "--color", &rgb), "--depth", &depth), "--out-dir", &out);
        a.extend(os(extra));
        a
    };
    let stitch = |extra: &[&str]| {
        let mut a = with(os(&["stitch", "--scene", "demo"]), "--out-dir", &out);
        a.extend(os(extra));
        a
    };
    let scene = |extra: &[&str]| {
        let mut a = with(os(&["scene"]), "--out-dir", &out);
        a.extend(os(extra));
        a
    };
    let cases: Vec<(&str, Vec<OsString>, &str)> = vec![
        ("writer threads 30000", batch(&["--writer-threads", "30000"]), "0..=64"),
        (
            "writer threads 100000",
            batch(&["--writer-threads", "100000"]),
            "0..=64",
        ),
        (
            "writer threads -1",
            batch(&["--writer-threads", "-1"]),
            // --writer-threads is the old name of --jobs: clap names the option it parsed.
            "--jobs",
        ),
        ("jobs 65", batch(&["--jobs", "65"]), "0..=64"),
        (
            "fx 1e308",
            refocus_k(["1e308", "40", "15.5", "11.5"]),
            "magnitude <= 1e6",
        ),
        ("fy nan", refocus_k(["40", "nan", "15.5", "11.5"]), "--fy"),
        ("fx inf", refocus_k(["inf", "40", "15.5", "11.5"]), "--fx"),
        ("cx text", refocus_k(["40", "40", "forty", "11.5"]), "not a number"),
        ("cy -1e9", refocus_k(["40", "40", "15.5", "-1e9"]), "--cy"),
        ("zoom 1e308", refocus(&["--zoom-range", "0.5,1e308"]), "--zoom-range"),
        ("focal list inf", refocus(&["--focal-list", "inf"]), "--focal-list"),
        ("tau-rel 1e308", refocus(&["--tau-rel", "1e308"]), "--tau-rel"),
        ("tau-abs nan", refocus(&["--tau-abs", "nan"]), "--tau-abs"),
        (
            "depth-scale 1e308",
            refocus(&["--depth-scale", "1e308"]),
            "--depth-scale",
        ),
        (
            "width-out 0",
            refocus(&["--width-out", "0", "--height-out", "10"]),
            "--width-out",
        ),
        (
            "height-out 16385",
            refocus(&["--width-out", "10", "--height-out", "16385"]),
            "1..=16384",
        ),
        (
            "height-out 2^32",
            refocus(&["--width-out", "10", "--height-out", "4294967296"]),
            "--height-out",
        ),
        (
            "cx-out 1e308",
            refocus(&["--cx-out", "1e308", "--cy-out", "1"]),
            "--cx-out",
        ),
        ("max-pixels 0", refocus(&["--max-pixels", "0"]), "--max-pixels"),
        ("max-pixels text", refocus(&["--max-pixels", "lots"]), "--max-pixels"),
        (
            "max-pixels 2^40",
            refocus(&["--max-pixels", "1099511627776"]),
            "--max-pixels",
        ),
        ("baseline 1e308", reproject(&["--baseline", "1e308"]), "--baseline"),
        ("doffs nan", reproject(&["--doffs", "nan"]), "--doffs"),
        ("steps 0", reproject(&["--steps", "0"]), "1..=16"),
        ("steps 17", reproject(&["--steps", "17"]), "1..=16"),
        (
            "near 1e308",
            reproject(&["--depth-kind", "device", "--near", "1e308", "--far", "10"]),
            "--near",
        ),
        (
            "far nan",
            reproject(&["--depth-kind", "device", "--near", "0.1", "--far", "nan"]),
            "--far",
        ),
        (
            "separation inf",
            reproject(&["--separation", "inf", "--convergence", "2"]),
            "--separation",
        ),
        ("stitch ipd 1e308", stitch(&["--ipd", "1e308"]), "--ipd"),
        ("stitch fov 1e308", stitch(&["--fov", "1e308"]), "--fov"),
        ("stitch pole-fade inf", stitch(&["--pole-fade", "inf"]), "--pole-fade"),
        ("stitch width 0", stitch(&["--width", "0"]), "--width"),
        ("stitch height 99999", stitch(&["--height", "99999"]), "--height"),
        ("stitch face-size 0", stitch(&["--face-size", "0"]), "--face-size"),
        ("scene width 0", scene(&["--width", "0"]), "--width"),
        ("scene ipd 1e308", scene(&["--ipd", "1e308"]), "--ipd"),
        (
            "report repeats 10^6",
            with(os(&["report", "--repeats", "1000000"]), "--out-dir", &out),
            "--repeats",
        ),
        ("bench repeats 5000", os(&["bench", "--repeats", "5000"]), "--repeats"),
        ("unknown flag", refocus(&["--no-such-flag"]), "--no-such-flag"),
    ];
    let mut failures = Vec::new();
    let n = cases.len();
    for (label, args, needle) in cases {
        sb.refuses(&mut failures, label, &args, 2, &[needle]);
    }
    // Values that parse but are out of range for the job: usage errors too (exit 2).
    let mut run_errors = 0;
    for (label, args, needle) in [
        (
            "stitch height 16384 (top-bottom too tall)",
            stitch(&["--height", "16384", "--width", "16"]),
            "top-bottom",
        ),
        (
            "scene 16384^2 above the budget",
            scene(&["--width", "16384", "--height", "16384"]),
            "pixel budget",
        ),
        (
            "refocus output above the budget",
            refocus(&["--width-out", "16384", "--height-out", "16384"]),
            "pixel budget",
        ),
    ] {
        run_errors += 1;
        sb.refuses(&mut failures, label, &args, 2, &[needle]);
    }
    // Found while running (exit 1): an input's contents, still before any output.
    std::fs::write(d.join("empty.csv"), "").unwrap();
    let args = with(
        with(os(&["refocus"]), "--batch", &d.join("empty.csv")),
        "--out-dir",
        &out,
    );
    run_errors += 1;
    sb.refuses(&mut failures, "batch empty manifest", &args, 1, &["empty.csv"]);
    assert_no_failures(failures, n + run_errors);
}

#[test]
fn error_messages_name_the_os_error_once() {
    let sb = Sandbox::new("os-error");
    let missing = sb.path("nope.png");
    let args = with(
        with(
            with(
                os(&["refocus", "--fx", "1", "--fy", "1", "--cx", "1", "--cy", "1"]),
                "--rgb",
                &missing,
            ),
            "--depth",
            &missing,
        ),
        "--out-dir",
        &sb.out,
    );
    let mut failures = Vec::new();
    sb.refuses(
        &mut failures,
        "missing input",
        &args,
        1,
        &["nope.png: No such file or directory (os error 2)"],
    );
    // An out-dir below a regular file.
    std::fs::write(sb.path("blocker"), b"x").unwrap();
    let (rgb, depth) = write_inputs(&sb.root, W, H, "");
    let args = with(
        with(
            with(
                os(&["refocus", "--fx", "40", "--fy", "40", "--cx", "15", "--cy", "11"]),
                "--rgb",
                &rgb,
            ),
            "--depth",
            &depth,
        ),
        "--out-dir",
        &sb.path("blocker/out"),
    );
    sb.refuses(
        &mut failures,
        "out-dir below a file",
        &args,
        1,
        &["blocker/out", "os error 20"],
    );
    assert_no_failures(failures, 2);
}

fn refocus_ok(rgb: &Path, depth: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut c = bin();
    c.args(["refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"])
        .arg("--rgb")
        .arg(rgb)
        .arg("--depth")
        .arg(depth)
        .arg("--out-dir")
        .arg(out)
        .args(extra);
    c.output().unwrap()
}

fn contents(dir: &Path) -> BTreeMap<PathBuf, Entry> {
    snapshot(dir, Path::new(""))
}

#[test]
fn symlinks_at_output_names_are_replaced_never_followed() {
    let sb = Sandbox::new("out-links");
    let (rgb, depth) = write_inputs(&sb.root, W, H, "");
    std::fs::create_dir_all(&sb.out).unwrap();
    let victim = sb.path("victim/precious.txt");
    for name in ["s1_rgb.png", "s1_depth.exr", "manifest.json"] {
        symlink(&victim, sb.out.join(name)).unwrap();
    }
    // Names the old write probe used, for any pid near ours.
    let me = std::process::id();
    for pid in me.saturating_sub(50)..me + 200 {
        symlink(&victim, sb.out.join(format!(".viewsynth-write-test-{pid}"))).unwrap();
    }
    let before = snapshot(&sb.root, &sb.out);
    let o = refocus_ok(&rgb, &depth, &sb.out, &["--zoom-range", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        snapshot(&sb.root, &sb.out),
        before,
        "a file outside the out-dir changed"
    );
    for name in ["s1_rgb.png", "s1_depth.exr", "manifest.json", "s1_mask.png"] {
        let m = std::fs::symlink_metadata(sb.out.join(name)).unwrap();
        assert!(m.is_file(), "{name} is not a regular file");
        // Created like any file (umask applies), not private 0600 temporaries.
        assert_ne!(
            m.permissions().mode() & 0o044,
            0,
            "{name} mode {:o}",
            m.permissions().mode()
        );
    }
    // Only the planted links remain of that prefix, untouched.
    let left: Vec<String> = temporaries(&sb.out)
        .into_iter()
        .filter(|f| !f.starts_with(".viewsynth-write-test-"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    let link = sb.out.join(format!(".viewsynth-write-test-{me}"));
    assert_eq!(std::fs::read_link(link).unwrap(), victim);
}

#[test]
fn a_failing_rerun_keeps_every_earlier_output() {
    let sb = Sandbox::new("rerun");
    let (rgb, depth) = write_inputs(&sb.root, W, H, "");
    let o = refocus_ok(&rgb, &depth, &sb.out, &["--zoom-range", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let first = contents(&sb.out);
    assert_eq!(first.len(), 4);
    // The second run's last file cannot be placed: a folder is in the way.
    std::fs::create_dir(sb.out.join("s2_mask.png")).unwrap();
    let first = contents(&sb.out);
    let o = refocus_ok(&rgb, &depth, &sb.out, &["--zoom-range", "1,2"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("s2_mask.png") && err.contains("folder"), "{err}");
    assert_eq!(contents(&sb.out), first, "the earlier outputs changed");

    // Cyclopean: a rerun that fails (the camera file became invalid, or an output cannot be
    // placed) leaves the earlier middle view whole.
    let cams = sb.path("cameras.json");
    std::fs::write(&cams, cameras_json("2.5")).unwrap();
    let cyc_out = sb.path("cyc");
    let cyclopean = || {
        let mut c = bin();
        c.arg("cyclopean");
        for (flag, p) in [
            ("--left-rgb", &rgb),
            ("--left-depth", &depth),
            ("--right-rgb", &rgb),
            ("--right-depth", &depth),
            ("--cameras", &cams),
            ("--out-dir", &cyc_out),
        ] {
            c.arg(flag).arg(p);
        }
        c.output().unwrap()
    };
    let o = cyclopean();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        files_in(&cyc_out),
        ["middle_depth.exr", "middle_mask.png", "middle_rgb.png"]
    );
    std::fs::remove_file(cyc_out.join("middle_rgb.png")).unwrap();
    std::fs::create_dir(cyc_out.join("middle_rgb.png")).unwrap();
    let kept = contents(&cyc_out);
    let o = cyclopean();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(contents(&cyc_out), kept);
    std::fs::write(&cams, cameras_json("1e308")).unwrap();
    let o = cyclopean();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(contents(&cyc_out), kept);
}

#[test]
fn concurrent_runs_into_one_folder_all_complete() {
    let sb = Sandbox::new("concurrent");
    let (rgb, depth) = write_inputs(&sb.root, W, H, "");
    let children: Vec<_> = (0..4)
        .map(|_| {
            let mut c = bin();
            c.args([
                "refocus",
                "--fx",
                "40",
                "--fy",
                "40",
                "--cx",
                "15.5",
                "--cy",
                "11.5",
                "--zoom-range",
                "0.5,1,2",
            ])
            .arg("--rgb")
            .arg(&rgb)
            .arg("--depth")
            .arg(&depth)
            .arg("--out-dir")
            .arg(&sb.out)
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
            c.spawn().unwrap()
        })
        .collect();
    for child in children {
        let o = child.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert!(temporaries(&sb.out).is_empty(), "{:?}", temporaries(&sb.out));
    assert_eq!(files_in(&sb.out).len(), 10);
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(sb.out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["outputs"].as_array().unwrap().len(), 3);
}

/// The set a folder's manifest names: each listed file's name and whether it is there with the
/// CRC-32 recorded; and the manifest's bytes (which run wrote it).
fn set_state(dir: &Path) -> (Vec<(String, bool)>, Vec<u8>) {
    let bytes = std::fs::read(dir.join("manifest.json")).expect("a manifest");
    let m: serde_json::Value = serde_json::from_slice(&bytes).expect("a whole manifest");
    let files = m["files"]
        .as_array()
        .expect("files")
        .iter()
        .map(|f| {
            let name = f["name"].as_str().unwrap().to_string();
            let want = f["crc32"].as_u64().expect("crc32");
            let ok = std::fs::read(dir.join(&name)).is_ok_and(|b| {
                let mut c = flate2::Crc::new();
                c.update(&b);
                u64::from(c.sum()) == want
            });
            (name, ok)
        })
        .collect();
    (files, bytes)
}

/// How many files the child's staging folder in `out` (`.viewsynth-<pid>-*`) holds besides its
/// lock, once the lock file exists (a folder killed before its lock file is made is only taken
/// as orphaned after a minute's grace, file_set.rs: not a point to kill at here).
fn staged(out: &Path, pid: u32) -> Option<usize> {
    let prefix = format!(".viewsynth-{pid}-");
    let dir = files_in(out)
        .into_iter()
        .find(|f| f.starts_with(&prefix) && out.join(f).is_dir())?;
    let files = files_in(&out.join(dir));
    files.iter().any(|f| f == ".viewsynth-lock").then(|| files.len() - 1)
}

/// kill -9 really mid-run, at several points chosen by what the run has staged (not by time:
/// the whole job takes ~0.4 s here), then the fault hook (`VIEWSYNTH_FAULT_AFTER`, the same
/// status 137 without destructors) after the journal and mid-renames, where a signal cannot be
/// aimed. Each kill must land before the run ends (killed by signal 9 / exit 137, never a
/// success); after it, and after the next start's recovery, the folder holds the old set or
/// the new set, complete (every file the manifest lists, with its CRC), and no temporary.
#[test]
fn kill_9_mid_run_then_rerun_leaves_the_old_or_the_new_set_complete() {
    use std::os::unix::process::ExitStatusExt;
    let sb = Sandbox::new("kill");
    let (rgb, depth) = write_inputs(&sb.root, W, H, "");
    let out = &sb.out;
    // The old set: one scale (s1_*, 4 files with the manifest).
    let o = refocus_ok(&rgb, &depth, out, &["--zoom-range", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (old_files, old_manifest) = set_state(out);
    assert_eq!(old_files.len(), 3);
    let pristine = sb.path("old-set");
    std::fs::create_dir(&pristine).unwrap();
    for f in files_in(out) {
        std::fs::copy(out.join(&f), pristine.join(&f)).unwrap();
    }
    // The new job: 12 scales x 3 files + the manifest, at 1024 x 768.
    let scales = "0.5,0.75,1,1.25,1.5,1.75,2,2.25,2.5,2.75,3,3.5";
    let job = |fault: Option<&str>| {
        let mut c = bin();
        c.args(["refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"])
            .args(["--zoom-range", scales, "--width-out", "1024", "--height-out", "768"])
            .arg("--rgb")
            .arg(&rgb)
            .arg("--depth")
            .arg(&depth)
            .arg("--out-dir")
            .arg(out)
            .stdout(Stdio::null())
            .stderr(Stdio::null());
        match fault {
            Some(k) => c.env("VIEWSYNTH_FAULT_AFTER", k),
            None => c.env_remove("VIEWSYNTH_FAULT_AFTER"),
        };
        c
    };
    let check = |label: &str, expect_new: Option<bool>| {
        let (files, manifest) = set_state(out);
        let is_new = manifest != old_manifest;
        assert!(
            files.iter().all(|(_, ok)| *ok),
            "{label}: the set is not complete: {files:?}"
        );
        if let Some(want) = expect_new {
            assert_eq!(is_new, want, "{label}: old set {} expected", !want);
        }
        assert_eq!(files.len(), if is_new { 36 } else { 3 }, "{label}");
        is_new
    };
    // Staged files at the kill: the folder just made, the first file, a third, two thirds.
    for at in [0, 1, 12, 24] {
        let mut child = job(None).spawn().unwrap();
        let pid = child.id();
        let t0 = std::time::Instant::now();
        loop {
            if staged(out, pid).is_some_and(|n| n >= at) {
                break;
            }
            assert!(t0.elapsed().as_secs() < 60, "nothing staged by the job after 60 s");
            if child.try_wait().unwrap().is_some() {
                break; // ended before the kill: caught below
            }
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
        child.kill().unwrap();
        let status = child.wait().unwrap();
        let label = format!("killed with {at} files staged");
        assert_eq!(
            status.signal(),
            Some(9),
            "{label}: the run ended before the kill ({status:?})"
        );
        // Killed before the journal: the old set is untouched, and no final name is new.
        check(&label, Some(false));
        let finals: Vec<String> = files_in(out)
            .into_iter()
            .filter(|f| !f.starts_with(".viewsynth-"))
            .collect();
        assert_eq!(finals.len(), 4, "{label}: {finals:?}");
        assert_eq!(
            temporaries(out).len(),
            1,
            "{label}: its staging folder stays until the next start"
        );
        io::OutDir::prepare(out).unwrap();
        check(&format!("{label}, recovered"), Some(false));
        assert!(temporaries(out).is_empty(), "{label}: {:?}", temporaries(out));
    }
    // After the journal (step 1) and mid-renames (step 20 of 40: journal, 36 renames, 3 cleanup):
    // recovery rolls forward to the new set.
    for k in ["1", "20"] {
        let o = job(Some(k)).output().unwrap();
        assert_eq!(o.status.code(), Some(137), "fault after step {k}");
        io::OutDir::prepare(out).unwrap();
        check(&format!("fault after step {k}, recovered"), Some(true));
        assert!(temporaries(out).is_empty(), "{:?}", temporaries(out));
        // Back to the old set for the next case.
        std::fs::remove_dir_all(out).unwrap();
        std::fs::create_dir(out).unwrap();
        for f in files_in(&pristine) {
            std::fs::copy(pristine.join(&f), out.join(&f)).unwrap();
        }
        check("old set restored", Some(false));
    }

    // Leftovers: a killed run's staging folder (its lock file unlocked), and a live run's
    // temporary and staging folder in another PID namespace (their pids mean nothing here:
    // pid 1 and one above any pid_max), owned through their locks, which must survive.
    let dead = out.join(".viewsynth-1-AbC123");
    std::fs::create_dir(&dead).unwrap();
    std::fs::write(dead.join("s1_rgb.png"), b"partial").unwrap();
    std::fs::write(dead.join(".viewsynth-lock"), b"").unwrap();
    let live = out.join(".viewsynth-1-XyZ789.tmp");
    std::fs::write(&live, b"someone else's").unwrap();
    let live_lock = std::fs::File::open(&live).unwrap();
    rustix::fs::flock(&live_lock, rustix::fs::FlockOperation::NonBlockingLockExclusive).unwrap();
    let foreign = out.join(format!(".viewsynth-{}-Other1", u32::MAX - 1));
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join(".viewsynth-lock"), b"").unwrap();
    let foreign_lock = std::fs::File::open(foreign.join(".viewsynth-lock")).unwrap();
    rustix::fs::flock(&foreign_lock, rustix::fs::FlockOperation::NonBlockingLockExclusive).unwrap();
    let o = refocus_ok(&rgb, &depth, out, &["--zoom-range", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut want = vec![
        ".viewsynth-1-XyZ789.tmp".to_string(),
        format!(".viewsynth-{}-Other1", u32::MAX - 1),
    ];
    want.sort();
    assert_eq!(temporaries(out), want);
    assert_eq!(std::fs::read(&live).unwrap(), b"someone else's");
    drop((live_lock, foreign_lock));
    assert!(files_in(out).contains(&"s1_rgb.png".to_string()));
}

#[test]
fn non_utf8_paths_work_and_are_shown() {
    let sb = Sandbox::new("non-utf8");
    let (rgb, depth) = write_inputs(&sb.root, W, H, "");
    let odd = |name: &[u8]| sb.root.join(OsStr::from_bytes(name));
    let (rgb2, depth2) = (odd(b"rgb-\xff.png"), odd(b"depth-\xfe.npy"));
    std::fs::copy(&rgb, &rgb2).unwrap();
    std::fs::copy(&depth, &depth2).unwrap();
    let out = odd(b"out-\xff");
    let o = refocus_ok(&rgb2, &depth2, &out, &["--zoom-range", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(files_in(&out).len(), 4);
    let missing = odd(b"gone-\xff.png");
    let o = refocus_ok(&missing, &depth2, &out, &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("gone-\u{fffd}.png"));
    let _ = OsString::from_vec(Vec::new());
}

#[test]
fn csv_manifest_with_a_byte_order_mark_is_read() {
    let sb = Sandbox::new("bom");
    write_inputs(&sb.root, W, H, "");
    let manifest = sb.path("frames.csv");
    std::fs::write(
        &manifest,
        "\u{feff}rgb,depth,fx,fy,cx,cy\nrgb.png,depth.npy,40,40,15.5,11.5\n",
    )
    .unwrap();
    let o = bin()
        .args(["refocus", "--zoom-range", "1", "--batch"])
        .arg(&manifest)
        .arg("--out-dir")
        .arg(&sb.out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The frame's folder beside the index: no `index.part-0-of-1.jsonl` without --shard.
    assert_eq!(files_in(&sb.out), ["00000_rgb", "index.jsonl"]);
}

#[test]
fn a_symlinked_subfolder_of_the_out_dir_is_refused_before_rendering() {
    let sb = Sandbox::new("demo-link");
    std::fs::create_dir_all(&sb.out).unwrap();
    symlink(sb.path("victim"), sb.out.join("stitch")).unwrap();
    let before = snapshot(&sb.root, &sb.out);
    let o = bin().arg("demo").arg("--out-dir").arg(&sb.out).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("stitch: is a symlink to") && err.contains("only written inside --out-dir"),
        "{err}"
    );
    assert_eq!(
        snapshot(&sb.root, &sb.out),
        before,
        "a file outside the out-dir changed"
    );
    // Nothing rendered: at most the (empty) subfolders made before the refusal.
    for f in files_in(&sb.out).iter().filter(|f| f.as_str() != "stitch") {
        assert!(files_in(&sb.out.join(f)).is_empty(), "{f} is not empty");
    }
}
