//! Every input is bounded before it is read: headers, containers (.npy, .npz), FIFOs and
//! devices, under an address-space limit far below what decoding would take.

use crate::common::assert_no_failures;
use std::path::Path;

use crate::cli::{files_in, scratch};
use crate::safety::support::{inputs, mkfifo, p, run, s, H, W};

fn npy_bytes(shape: &str, descr: &str, payload: &[u8]) -> Vec<u8> {
    let mut dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend((dict.len() as u16).to_le_bytes());
    out.extend(dict.as_bytes());
    out.extend(payload);
    out
}

/// An `.npz` as numpy's savez writes one (zip64 local headers, real CRCs, a central
/// directory): each member is `bytes` and then `zeros` zero bytes (streamed, never held),
/// deflated at the best level with `deflate`.
fn npz(members: &[(&str, &[u8], u64)], deflate: bool) -> Vec<u8> {
    use std::io::Write;
    let method = if deflate {
        zip::CompressionMethod::Deflated
    } else {
        zip::CompressionMethod::Stored
    };
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(method)
        .compression_level(deflate.then_some(9))
        .large_file(true);
    let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let chunk = vec![0u8; 1 << 20];
    for &(name, bytes, zeros) in members {
        w.start_file(name, options).unwrap();
        w.write_all(bytes).unwrap();
        let mut left = zeros;
        while left > 0 {
            let n = left.min(chunk.len() as u64) as usize;
            w.write_all(&chunk[..n]).unwrap();
            left -= n as u64;
        }
    }
    w.finish().unwrap().into_inner()
}

#[test]
fn every_input_is_bounded_before_it_is_read() {
    let root = scratch("r3-inputs");
    let (rgb, depth) = inputs(&root);
    let (r, d, o) = (p(&rgb), p(&depth), p(&root.join("out")));
    // The NPZ bomb of the issue: (4, 8192, 8192) float64 declared, 2 GB inflated, ~2 MB stored.
    let header = npy_bytes("(4, 8192, 8192)", "<f8", &[]);
    let payload = 4u64 * 8192 * 8192 * 8;
    let bomb = root.join("bomb.npz");
    std::fs::write(&bomb, npz(&[("arr_0.npy", &header, payload)], true)).unwrap();
    // Two members of one name.
    let one = npy_bytes(&format!("({H}, {W})"), "<f4", &vec![0u8; (W * H * 4) as usize]);
    let dup = root.join("dup.npz");
    // The zip writer refuses a repeated name: the second is renamed in its headers after.
    let mut two = npz(&[("arr_0.npy", &one, 0), ("arr_1.npy", &one, 0)], false);
    while let Some(at) = two.windows(9).position(|w| w == b"arr_1.npy") {
        two[at..at + 9].copy_from_slice(b"arr_0.npy");
    }
    std::fs::write(&dup, two).unwrap();
    // A 3-D member within the value budget but no depth: refused from its header.
    let cube = npy_bytes("(3, 2, 2)", "<f4", &[0u8; 48]);
    let cube_npz = root.join("cube.npz");
    std::fs::write(&cube_npz, npz(&[("arr_0.npy", &cube, 0)], false)).unwrap();
    // Intrinsics: huge sparse text file, FIFO, device, huge/subnormal values.
    let big = root.join("big.txt");
    std::fs::File::create(&big).unwrap().set_len(128 << 20).unwrap();
    let fifo = root.join("k.fifo");
    mkfifo(&fifo);
    let k = |name: &str, text: &str| {
        let path = root.join(name);
        std::fs::write(&path, text).unwrap();
        p(&path)
    };
    let k_huge = k("k_huge.txt", "1e300 0 16 0 40 12 0 0 1");
    let k_tiny = k("k_tiny.txt", "5e-324 0 16 0 40 12 0 0 1");
    let k_cx = k("k_cx.txt", "40 0 1e9 0 40 12 0 0 1");
    // A 15 MB JSON key.
    let key_json = root.join("cams.json");
    std::fs::write(&key_json, format!("{{\"{}\": 1}}", "k".repeat(15 << 20))).unwrap();
    let manifest_long = root.join("long.csv");
    std::fs::write(
        &manifest_long,
        format!("rgb,depth,fx,fy,cx,cy\n{},{d},40,40,15,11\n", "r".repeat(15 << 20)),
    )
    .unwrap();
    let refocus_k = |k: &str| {
        s(&[
            "refocus",
            "--rgb",
            &r,
            "--depth",
            &d,
            "--out-dir",
            &o,
            "--intrinsics",
            k,
        ])
    };
    let refocus_depth = |dp: &Path| {
        s(&[
            "refocus",
            "--rgb",
            &r,
            "--depth",
            &p(dp),
            "--out-dir",
            &o,
            "--fx",
            "40",
            "--fy",
            "40",
            "--cx",
            "15",
            "--cy",
            "11",
        ])
    };
    let cases: Vec<(&str, Vec<String>, i32, &str)> = vec![
        ("npz bomb", refocus_depth(&bomb), 1, "pixel budget"),
        (
            "npz duplicate members",
            refocus_depth(&dup),
            1,
            "two arrays named 'arr_0'",
        ),
        ("npz 3-D member", refocus_depth(&cube_npz), 1, "(H, W)"),
        ("intrinsics 128 MB", refocus_k(&p(&big)), 1, "big.txt"),
        ("intrinsics FIFO", refocus_k(&p(&fifo)), 1, "FIFO"),
        ("intrinsics /dev/zero", refocus_k("/dev/zero"), 1, "character device"),
        ("intrinsics fx 1e300", refocus_k(&k_huge), 1, "fx"),
        ("intrinsics fx 5e-324", refocus_k(&k_tiny), 1, "fx"),
        ("intrinsics cx 1e9", refocus_k(&k_cx), 1, "cx"),
        (
            "cameras 15 MB key",
            s(&[
                "cyclopean",
                "--left-rgb",
                &r,
                "--right-rgb",
                &r,
                "--left-depth",
                &d,
                "--right-depth",
                &d,
            ])
            .into_iter()
            .chain(s(&["--cameras", &p(&key_json), "--out-dir", &o]))
            .collect(),
            1,
            "cams.json",
        ),
        (
            "manifest 15 MB cell",
            s(&["refocus", "--batch", &p(&manifest_long), "--out-dir", &o]),
            1,
            "long.csv",
        ),
    ];
    let mut failures = Vec::new();
    let n = cases.len();
    for (label, args, code, needle) in cases {
        let res = run(&args);
        let err = String::from_utf8_lossy(&res.stderr);
        let mut problems = Vec::new();
        if res.status.code() != Some(code) {
            problems.push(format!("exit {:?}", res.status.code()));
        }
        if !err.contains(needle) {
            problems.push(format!("message lacks '{needle}'"));
        }
        // Whatever the input holds, the message quotes a short excerpt of it.
        if err.len() > 8192 {
            problems.push(format!("message of {} bytes", err.len()));
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{label}: {} -- {}",
                problems.join("; "),
                &err[..err.len().min(400)]
            ));
        }
    }
    assert!(!root.join("out").exists() || files_in(&root.join("out")).is_empty());
    assert_no_failures(failures, n);
}
