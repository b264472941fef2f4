//! `.npz` archives built here as numpy writes them (stored, deflated, zip64 local headers),
//! (the real Middlebury 2014 Motorcycle disparity: cli/tests/integration/reproject.rs).

use super::*;
use crate::io::npy::build_npy;
use std::io::Write;

/// A zip local header + data as Python's zipfile writes it (numpy's savez forces zip64).
fn member(name: &str, npy: &[u8], deflate: bool, zip64: bool) -> Vec<u8> {
    let data = if deflate {
        let mut e = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(npy).unwrap();
        e.finish().unwrap()
    } else {
        npy.to_vec()
    };
    let mut h = Vec::new();
    h.extend_from_slice(&LOCAL_HEADER.to_le_bytes());
    h.extend_from_slice(&45u16.to_le_bytes()); // version needed
    h.extend_from_slice(&0u16.to_le_bytes()); // flags
    h.extend_from_slice(&(if deflate { 8u16 } else { 0 }).to_le_bytes());
    h.extend_from_slice(&[0; 8]); // time, date, crc (not checked)
    let (packed, unpacked) = if zip64 {
        (u32::MAX, u32::MAX)
    } else {
        (data.len() as u32, npy.len() as u32)
    };
    h.extend_from_slice(&packed.to_le_bytes());
    h.extend_from_slice(&unpacked.to_le_bytes());
    h.extend_from_slice(&(name.len() as u16).to_le_bytes());
    h.extend_from_slice(&(if zip64 { 20u16 } else { 0 }).to_le_bytes());
    h.extend_from_slice(name.as_bytes());
    if zip64 {
        h.extend_from_slice(&ZIP64_EXTRA.to_le_bytes());
        h.extend_from_slice(&16u16.to_le_bytes());
        h.extend_from_slice(&(npy.len() as u64).to_le_bytes());
        h.extend_from_slice(&(data.len() as u64).to_le_bytes());
    }
    h.extend_from_slice(&data);
    h
}

fn f4(shape: &str, values: &[f32]) -> Vec<u8> {
    let payload: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    build_npy(
        &format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape}, }}"),
        &payload,
    )
}

fn u1(values: &[u8]) -> Vec<u8> {
    build_npy(
        &format!(
            "{{'descr': '|u1', 'fortran_order': False, 'shape': ({},), }}",
            values.len()
        ),
        values,
    )
}

fn write(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("viewsynth-npz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn stored_deflated_and_zip64_members_read_alike() {
    let values = [1.0, 2.5, f32::INFINITY, 0.0, 7.0, 3.25];
    let npy = f4("(2, 3)", &values);
    for (deflate, zip64) in [(false, false), (true, false), (false, true), (true, true)] {
        let p = write(
            &format!("one_{deflate}_{zip64}.npz"),
            &member("arr_0.npy", &npy, deflate, zip64),
        );
        let (key, a) = load_npz_array(&p, None).unwrap();
        assert_eq!(key, "arr_0");
        assert_eq!(a.shape, [2, 3]);
        let want: Vec<f64> = values.iter().map(|v| *v as f64).collect();
        assert_eq!(a.data, want, "deflate {deflate} zip64 {zip64}");
    }
}

#[test]
fn default_key_is_the_first_float_array_and_a_key_picks_another() {
    let mut zip = member("labels.npy", &u1(&[1, 2, 3]), true, true);
    zip.extend(member("depth.npy", &f4("(1, 2)", &[4.0, 5.0]), true, true));
    zip.extend(member("conf.npy", &f4("(1, 2)", &[0.5, 0.25]), false, true));
    let p = write("several.npz", &zip);
    let (key, a) = load_npz_array(&p, None).unwrap();
    assert_eq!((key.as_str(), a.data.as_slice()), ("depth", [4.0, 5.0].as_slice()));
    let (_, conf) = load_npz_array(&p, Some("conf")).unwrap();
    assert_eq!(conf.data, [0.5, 0.25]);
    let e = load_npz_array(&p, Some("disp")).unwrap_err().to_string();
    assert!(
        e.contains("several.npz") && e.contains("'disp'") && e.contains("labels, depth, conf"),
        "{e}"
    );
    let ints = write(
        "ints.npz",
        &[
            member("a.npy", &u1(&[1]), false, false),
            member("b.npy", &u1(&[2]), false, false),
        ]
        .concat(),
    );
    let e = load_npz_array(&ints, None).unwrap_err().to_string();
    assert!(e.contains("no floating-point array") && e.contains("--npz-key"), "{e}");
}

#[test]
fn broken_archives_are_refused_with_the_file_named() {
    let npy = f4("(1, 2)", &[4.0, 5.0]);
    let whole = member("arr_0.npy", &npy, true, false);
    let cases = [
        ("truncated.npz", whole[..whole.len() - 3].to_vec(), "runs past the end"),
        ("not_zip.npz", b"hello".to_vec(), "not a zip archive"),
        (
            "bad_npy.npz",
            member("arr_0.npy", b"\x93NUMPY garbage", false, false),
            "invalid NPY",
        ),
    ];
    for (name, bytes, want) in cases {
        let e = load_npz_array(&write(name, &bytes), None).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains(want), "{name}: {e}");
    }
}
