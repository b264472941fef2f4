//! `.npz` archives written here by the zip crate as numpy's zipfile writes them (stored or
//! deflated, zip64 local headers, real CRCs, a central directory), then damaged byte by byte
//! for the hostile cases (the real Middlebury 2014 Motorcycle disparity:
//! viewsynth_tests/tests/library/reproject.rs).

use super::*;
use crate::io::formats::npy::build_npy;
use std::io::Write;
use zip::write::SimpleFileOptions;

/// An archive of `(name, .npy bytes, deflated)` members; zip64 local headers with `zip64`
/// (numpy's savez forces them).
fn npz(members: &[(&str, &[u8], bool)], zip64: bool) -> Vec<u8> {
    let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for &(name, data, deflate) in members {
        let method = if deflate {
            CompressionMethod::Deflated
        } else {
            CompressionMethod::Stored
        };
        let options = SimpleFileOptions::default()
            .compression_method(method)
            .large_file(zip64);
        w.start_file(name, options).unwrap();
        w.write_all(data).unwrap();
    }
    w.finish().unwrap().into_inner()
}

/// Where the `n`th central directory header starts.
fn central(zip: &[u8], n: usize) -> usize {
    let at = zip.windows(4).enumerate().filter(|(_, w)| *w == b"PK\x01\x02").nth(n);
    at.expect("central directory header").0
}

fn put(zip: &mut [u8], at: usize, bytes: &[u8]) {
    zip[at..at + bytes.len()].copy_from_slice(bytes);
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

fn refusal(name: &str, bytes: &[u8]) -> String {
    load_npz_array(&write(name, bytes), None).unwrap_err().to_string()
}

#[test]
fn stored_deflated_and_zip64_members_read_alike() {
    let values = [1.0, 2.5, f32::INFINITY, 0.0, 7.0, 3.25];
    let npy = f4("(2, 3)", &values);
    for (deflate, zip64) in [(false, false), (true, false), (false, true), (true, true)] {
        let p = write(
            &format!("one_{deflate}_{zip64}.npz"),
            &npz(&[("arr_0.npy", &npy, deflate)], zip64),
        );
        let (key, a) = load_npz_array(&p, None).unwrap();
        assert_eq!(key, "arr_0");
        assert_eq!(a.shape, [2, 3]);
        let want: Vec<f64> = values.iter().map(|v| *v as f64).collect();
        assert_eq!(a.data, want, "deflate {deflate} zip64 {zip64}");
    }
}

#[test]
fn zips_written_to_a_pipe_read_too() {
    // A writer that cannot seek puts each member's sizes and CRC in a data descriptor after its
    // data: a gap between members that hides none.
    let mut w = zip::ZipWriter::new_stream(Vec::new());
    let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
    for (name, values) in [("depth.npy", [4.0, 5.0]), ("conf.npy", [0.5, 0.25])] {
        w.start_file(name, options).unwrap();
        w.write_all(&f4("(1, 2)", &values)).unwrap();
    }
    let bytes = w.finish().unwrap().into_inner();
    assert_ne!(bytes[6] & 0x8, 0, "the first member has a data descriptor");
    let p = write("piped.npz", &bytes);
    assert_eq!(load_npz_array(&p, Some("conf")).unwrap().1.data, [0.5, 0.25]);
    assert_eq!(load_npz_array(&p, None).unwrap().1.data, [4.0, 5.0]);
}

#[test]
fn default_key_is_the_first_float_array_and_a_key_picks_another() {
    let labels = u1(&[1, 2, 3]);
    let depth = f4("(1, 2)", &[4.0, 5.0]);
    let conf = f4("(1, 2)", &[0.5, 0.25]);
    let zip = npz(
        &[
            ("labels.npy", &labels, true),
            ("depth.npy", &depth, true),
            ("conf.npy", &conf, false),
        ],
        true,
    );
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
    let ints = npz(&[("a.npy", &u1(&[1]), false), ("b.npy", &u1(&[2]), false)], false);
    let e = refusal("ints.npz", &ints);
    assert!(e.contains("no floating-point array") && e.contains("--npz-key"), "{e}");
}

#[test]
fn broken_archives_are_refused_with_the_file_named() {
    let npy = f4("(1, 2)", &[4.0, 5.0]);
    let whole = npz(&[("arr_0.npy", &npy, true)], false);
    // A method numpy never writes (bzip2), in the local and the central header.
    let mut bzip2 = npz(&[("arr_0.npy", &npy, false)], false);
    put(&mut bzip2, 8, &12u16.to_le_bytes());
    let c = central(&bzip2, 0);
    put(&mut bzip2, c + 10, &12u16.to_le_bytes());
    // The directory says the member's data is longer than the bytes before the directory.
    let mut long = npz(&[("arr_0.npy", &npy, false)], false);
    let c = central(&long, 0);
    put(&mut long, c + 20, &(npy.len() as u32 + 40).to_le_bytes());
    let cases = [
        ("truncated.npz", whole[..whole.len() - 3].to_vec(), "truncated"),
        ("not_zip.npz", b"hello".to_vec(), "not a zip archive"),
        (
            "bad_npy.npz",
            npz(&[("arr_0.npy", b"\x93NUMPY garbage", false)], false),
            "invalid NPY",
        ),
        ("bzip2.npz", bzip2, "compression method"),
        ("runs_past.npz", long, "runs past the end"),
        ("empty.npz", npz(&[], false), "no arrays"),
    ];
    for (name, bytes, want) in cases {
        let e = refusal(name, &bytes);
        assert!(e.contains(name) && e.contains(want), "{name}: {e}");
    }
}

#[test]
fn a_wrong_checksum_is_refused() {
    let values = [4.0f32, 5.0];
    let npy = f4("(1, 2)", &values);
    // A flipped bit in the stored payload, its CRC left as written.
    let mut flipped = npz(&[("arr_0.npy", &npy, false)], true);
    let at = flipped.windows(4).position(|w| w == 5.0f32.to_le_bytes()).unwrap();
    flipped[at] ^= 1;
    // A deflated member whose directory CRC is wrong.
    let mut crc = npz(&[("disp.npy", &npy, true)], true);
    let c = central(&crc, 0);
    crc[c + 16] ^= 0xff;
    for (name, bytes, key) in [("flipped.npz", flipped, "arr_0"), ("crc.npz", crc, "disp")] {
        let e = refusal(name, &bytes);
        assert!(
            e.contains(name) && e.contains(key) && e.contains("checksum"),
            "{name}: {e}"
        );
    }
}

#[test]
fn the_budget_and_the_declared_size_bound_what_is_inflated() {
    // Over the value budget: refused from the header.
    let p = write(
        "budget.npz",
        &npz(&[("arr_0.npy", &f4("(2, 3)", &[0.0; 6]), true)], true),
    );
    let e = load_npz_array_within(&p, None, 5, &|_| Ok(())).unwrap_err().to_string();
    assert!(e.contains("budget.npz") && e.contains("pixel budget"), "{e}");
    // Declared as a (1, 2) array but inflating 1 MiB past it: inflation stops one byte past
    // the declared size.
    let mut big = f4("(1, 2)", &[4.0, 5.0]);
    let declared = big.len() as u32;
    big.resize(big.len() + (1 << 20), 0);
    let mut zip = npz(&[("arr_0.npy", &big, true)], false);
    let c = central(&zip, 0);
    put(&mut zip, c + 24, &declared.to_le_bytes());
    let e = refusal("bomb.npz", &zip);
    assert!(e.contains("bomb.npz") && e.contains("trailing bytes"), "{e}");
}

#[test]
fn ambiguous_overlapping_and_crowded_archives_are_refused() {
    let (a, b) = (f4("(1, 1)", &[1.0]), f4("(1, 1)", &[2.0]));
    // Two members of one name: the central directory keeps one, the other hides between.
    let mut dup = npz(&[("arr_0.npy", &a, false), ("arr_1.npy", &b, false)], true);
    while let Some(at) = dup.windows(9).position(|w| w == b"arr_1.npy") {
        put(&mut dup, at, b"arr_0.npy");
    }
    // Two names of one key.
    let alias = npz(&[("a", &a, false), ("a.npy", &b, false)], false);
    // The second member's directory entry points at the first member.
    let mut overlap = npz(&[("x.npy", &a, false), ("y.npy", &b, false)], false);
    let c = central(&overlap, 1);
    put(&mut overlap, c + 42, &0u32.to_le_bytes());
    // An end record counting 65535 entries in a directory of one.
    let mut count = npz(&[("x.npy", &a, false)], false);
    let end = count.windows(4).rposition(|w| w == b"PK\x05\x06").unwrap();
    put(&mut count, end + 8, &[0xff; 4]);
    let names: Vec<String> = (0..=MAX_MEMBERS).map(|i| format!("m{i}.npy")).collect();
    let crowd: Vec<(&str, &[u8], bool)> = names.iter().map(|n| (n.as_str(), &a[..], false)).collect();
    let cases = [
        ("dup.npz", dup, "two arrays named 'arr_0'"),
        ("alias.npz", alias, "two arrays named 'a'"),
        ("overlap.npz", overlap, "overlaps"),
        ("count.npz", count, "not a zip archive"),
        ("crowd.npz", npz(&crowd, false), "more than 1024"),
    ];
    for (name, bytes, want) in cases {
        let e = refusal(name, &bytes);
        assert!(e.contains(name) && e.contains(want), "{name}: {e}");
    }
}

/// Without a key the first floating-point array is read, whatever comes before it: a boolean
/// mask (a dtype the reader does not decode) is passed over (it refused the archive).
#[test]
fn a_boolean_array_before_the_depth_is_passed_over() {
    let mask = build_npy("{'descr': '|b1', 'fortran_order': False, 'shape': (3,), }", &[1, 0, 1]);
    let depth = f4("(1, 3)", &[1.0, 2.0, 3.0]);
    let p = write(
        "bool_first.npz",
        &npz(&[("valid.npy", &mask, false), ("depth.npy", &depth, true)], false),
    );
    let (key, a) = load_npz_array(&p, None).unwrap();
    assert_eq!((key.as_str(), a.data), ("depth", vec![1.0, 2.0, 3.0]));
    // Named, the boolean array is still refused for its type.
    let e = load_npz_array(&p, Some("valid")).unwrap_err().to_string();
    assert!(e.contains("unsupported dtype '|b1'"), "{e}");
}
