//! The batch manifest: a CSV or JSON list of frames, streamed from the file (see the
//! module notes of [`super`]).

use super::index_names::is_index_name;
use crate::camera::Intrinsics;
use crate::error::{Error, Result};
use serde::Deserialize;
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

/// One frame of a batch manifest (a CSV row or a JSON object).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatchFrame {
    /// Output folder name; when absent, the row index and the colour file's stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Colour image path, relative to the manifest.
    pub rgb: PathBuf,
    /// Depth map path, relative to the manifest.
    pub depth: PathBuf,
    /// Focal length x of the source, pixels.
    pub fx: f64,
    /// Focal length y of the source, pixels.
    pub fy: f64,
    /// Principal point x of the source, pixels (OpenCV: pixel centres at integers).
    pub cx: f64,
    /// Principal point y of the source, pixels.
    pub cy: f64,
    /// Divisor from stored depth to metres (see [`DepthDecode`]); required for integer depth.
    #[serde(default)]
    pub depth_scale: Option<f64>,
    /// SUN RGB-D's bit rotation of 16-bit PNG depth.
    #[serde(default)]
    pub sun_bit_rotate: bool,
}

impl BatchFrame {
    pub(super) fn intrinsics(&self) -> Intrinsics {
        Intrinsics {
            fx: self.fx,
            fy: self.fy,
            cx: self.cx,
            cy: self.cy,
        }
    }
}

/// Largest CSV manifest: about 10^6 rows of absolute paths.
pub const MAX_MANIFEST_BYTES: u64 = 256 << 20;
/// Largest JSON manifest (the JSON inputs' cap).
pub const MAX_JSON_MANIFEST_BYTES: u64 = crate::io::MAX_JSON_BYTES;
/// Largest CSV row: two paths of PATH_MAX and the numbers fit; a longer row is refused before
/// more of it is buffered.
pub const MAX_MANIFEST_ROW_BYTES: u64 = 16 << 10;
/// Most frames one manifest lists (each costs its paths and name in memory until rendered).
pub const MAX_MANIFEST_ROWS: usize = 1_000_000;
/// The csv reader's buffer: what it may read ahead of the row being parsed.
const CSV_BUFFER: usize = 8 << 10;

/// Read a CSV or JSON manifest; every frame gets a unique, filesystem-safe name. The file is
/// streamed (see the module notes): memory is bounded per row, never the file's size twice.
pub fn load_manifest(path: &Path) -> Result<Vec<BatchFrame>> {
    load_manifest_with_defaults(path, [None; 4])
}

/// [`load_manifest`], with `defaults` (fx, fy, cx, cy) for frames that lack them, as
/// `--depth-scale` is for `depth_scale`: a row's own value wins, and a column may be left out.
pub fn load_manifest_with_defaults(path: &Path, defaults: [Option<f64>; 4]) -> Result<Vec<BatchFrame>> {
    let json = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let most = if json {
        MAX_JSON_MANIFEST_BYTES
    } else {
        MAX_MANIFEST_BYTES
    };
    let (file, len) = crate::io::open_regular(path)?;
    crate::io::check_file_len(path, len, most, "a batch manifest")?;
    // Spreadsheets save CSV (and editors JSON) with a UTF-8 byte-order mark: skipped.
    let mut file = std::io::BufReader::with_capacity(CSV_BUFFER, file.take(most));
    if file
        .fill_buf()
        .map_err(|e| Error::io(path, e))?
        .starts_with(b"\xef\xbb\xbf")
    {
        file.consume(3);
    }
    let mut frames: Vec<BatchFrame> = if json {
        let rows: Vec<JsonFrame> = serde_json::from_reader(file).map_err(|e| Error::decode(path, e.to_string()))?;
        let mut frames = Vec::with_capacity(rows.len());
        for (i, r) in rows.into_iter().enumerate() {
            let [fx, fy, cx, cy] = frame_intrinsics(path, i, [r.fx, r.fy, r.cx, r.cy], defaults)?;
            frames.push(BatchFrame {
                name: r.name,
                rgb: r.rgb,
                depth: r.depth,
                fx,
                fy,
                cx,
                cy,
                depth_scale: r.depth_scale,
                sun_bit_rotate: r.sun_bit_rotate,
            });
        }
        frames
    } else {
        parse_csv(path, file, defaults)?
    };
    if frames.len() > MAX_MANIFEST_ROWS {
        return Err(Error::decode(
            path,
            format!("{} frames: at most {MAX_MANIFEST_ROWS} per manifest", frames.len()),
        ));
    }
    if frames.is_empty() {
        return Err(Error::decode(path, "the manifest lists no frame"));
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let mut seen = std::collections::HashSet::new();
    for (i, f) in frames.iter_mut().enumerate() {
        for p in [&mut f.rgb, &mut f.depth] {
            if p.is_relative() {
                *p = base.join(&*p);
            }
        }
        let stem = f
            .rgb
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let name = f.name.clone().unwrap_or_else(|| format!("{i:05}_{stem}"));
        let safe = frame_folder_name(&name);
        if !is_frame_folder_name(&safe) || !seen.insert(safe.clone()) {
            return Err(Error::decode(
                path,
                format!(
                    "frame {i}: name '{}' is empty, hidden, longer than 255 bytes, one of the index's names \
                     (index.jsonl, index.part-K-of-N.jsonl) or repeated",
                    crate::error::excerpt(&name)
                ),
            ));
        }
        f.name = Some(safe);
    }
    Ok(frames)
}

/// `name` with every character a frame's folder name may not hold (all but ASCII letters,
/// digits, '-', '_', '.') replaced by '_': what [`load_manifest`] makes of a manifest's names.
pub fn frame_folder_name(name: &str) -> String {
    name.chars().map(|c| if folder_char(c) { c } else { '_' }).collect()
}

/// Whether `name` is one safe folder inside the output folder as it stands: non-empty, not
/// hidden (no leading '.', so never `.` or `..`), at most 255 bytes (NAME_MAX, so a huge name is
/// refused before any write), only ASCII letters, digits, '-', '_', '.', and not one of the
/// index's names at the out-dir root ([`is_index_name`]: a folder there would break every
/// later index write). A manifest's names are made so ([`frame_folder_name`]) or refused;
/// frames named by a caller (Python's refocus_batch) must be.
pub fn is_frame_folder_name(name: &str) -> bool {
    !name.is_empty()
        && !name.starts_with('.')
        && name.len() <= 255
        && name.chars().all(folder_char)
        && !is_index_name(name)
}

fn folder_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || "-_.".contains(c)
}

/// One manifest row as the CSV gives it: columns found by header name (others ignored),
/// empty optional cells absent.
#[derive(Deserialize)]
struct CsvFrame {
    #[serde(default)]
    name: Option<String>,
    rgb: PathBuf,
    depth: PathBuf,
    #[serde(default)]
    fx: Option<f64>,
    #[serde(default)]
    fy: Option<f64>,
    #[serde(default)]
    cx: Option<f64>,
    #[serde(default)]
    cy: Option<f64>,
    #[serde(default)]
    depth_scale: Option<f64>,
    #[serde(default)]
    sun_bit_rotate: Option<String>,
}

/// A JSON manifest's frame: [`BatchFrame`] with the intrinsics optional (defaults fill them).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonFrame {
    #[serde(default)]
    name: Option<String>,
    rgb: PathBuf,
    depth: PathBuf,
    #[serde(default)]
    fx: Option<f64>,
    #[serde(default)]
    fy: Option<f64>,
    #[serde(default)]
    cx: Option<f64>,
    #[serde(default)]
    cy: Option<f64>,
    #[serde(default)]
    depth_scale: Option<f64>,
    #[serde(default)]
    sun_bit_rotate: bool,
}

/// The source intrinsics of frame `i`: its own values, else the defaults, else refused by name.
fn frame_intrinsics(path: &Path, i: usize, own: [Option<f64>; 4], defaults: [Option<f64>; 4]) -> Result<[f64; 4]> {
    let mut k = [0.0; 4];
    for (j, name) in ["fx", "fy", "cx", "cy"].into_iter().enumerate() {
        k[j] = own[j].or(defaults[j]).ok_or_else(|| {
            Error::decode(
                path,
                format!(
                    "frame {i}: no {name}: give the manifest a {name} value or a default (--{name} or --intrinsics)"
                ),
            )
        })?;
    }
    Ok(k)
}

/// A reader that refuses to read more than `limit` bytes from the start (the parser moves the
/// limit on after each row), so a row without an end is refused after a bounded read.
struct RowBound<R> {
    inner: R,
    read: u64,
    limit: std::rc::Rc<std::cell::Cell<u64>>,
}

/// The error [`RowBound`] reads as, found again by [`csv_error`].
const ROW_TOO_LONG: &str = "row too long";

impl<R: Read> Read for RowBound<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let allowed = self.limit.get().saturating_sub(self.read);
        if allowed == 0 {
            // At the limit: only the end of the file is fine.
            let mut probe = [0u8; 1];
            return match self.inner.read(&mut probe)? {
                0 => Ok(0),
                _ => Err(std::io::Error::other(ROW_TOO_LONG)),
            };
        }
        let n = buf.len().min(usize::try_from(allowed).unwrap_or(usize::MAX));
        let n = self.inner.read(&mut buf[..n])?;
        self.read += n as u64;
        Ok(n)
    }
}

fn parse_csv(path: &Path, file: impl Read, defaults: [Option<f64>; 4]) -> Result<Vec<BatchFrame>> {
    // The reader may buffer ahead of the row it parses; the row itself gets MAX_MANIFEST_ROW_BYTES.
    let slack = MAX_MANIFEST_ROW_BYTES + CSV_BUFFER as u64;
    let limit = std::rc::Rc::new(std::cell::Cell::new(slack));
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .buffer_capacity(CSV_BUFFER)
        .from_reader(RowBound {
            inner: file,
            read: 0,
            limit: limit.clone(),
        });
    let header = reader
        .headers()
        .map_err(|e| csv_error(path, &csv::StringRecord::new(), None, e))?
        .clone();
    if header.iter().all(str::is_empty) {
        return Err(Error::decode(path, "empty manifest"));
    }
    let defaulted = ["fx", "fy", "cx", "cy"]
        .into_iter()
        .zip(defaults)
        .filter(|(_, d)| d.is_some());
    let defaulted: Vec<&str> = defaulted.map(|(n, _)| n).collect();
    for r in ["rgb", "depth", "fx", "fy", "cx", "cy"] {
        if !header.iter().any(|c| c == r) && !defaulted.contains(&r) {
            return Err(Error::decode(
                path,
                format!("header lacks column '{r}' (needs rgb,depth,fx,fy,cx,cy; fx,fy,cx,cy may come from --fx/--fy/--cx/--cy or --intrinsics)"),
            ));
        }
    }
    let mut frames = Vec::new();
    // One record buffer for every row: a row is parsed into its frame, then the buffer reused.
    let mut record = csv::StringRecord::new();
    loop {
        limit.set(reader.position().byte() + slack);
        if !reader
            .read_record(&mut record)
            .map_err(|e| csv_error(path, &header, None, e))?
        {
            break;
        }
        if frames.len() == MAX_MANIFEST_ROWS {
            return Err(Error::decode(
                path,
                format!("more than {MAX_MANIFEST_ROWS} frames: split the manifest (--shard runs share one)"),
            ));
        }
        let row: CsvFrame = record
            .deserialize(Some(&header))
            .map_err(|e| csv_error(path, &header, Some(&record), e))?;
        let [fx, fy, cx, cy] = frame_intrinsics(path, frames.len(), [row.fx, row.fy, row.cx, row.cy], defaults)?;
        frames.push(BatchFrame {
            name: row.name.filter(|s| !s.is_empty()),
            rgb: row.rgb,
            depth: row.depth,
            fx,
            fy,
            cx,
            cy,
            depth_scale: row.depth_scale,
            sun_bit_rotate: row
                .sun_bit_rotate
                .is_some_and(|v| v == "1" || v.eq_ignore_ascii_case("true")),
        });
    }
    Ok(frames)
}

/// The decode error of a manifest line: "line 3: 5 cells, header has 6" or
/// "line 2: cy = 'abc': invalid float literal".
fn csv_error(path: &Path, header: &csv::StringRecord, record: Option<&csv::StringRecord>, e: csv::Error) -> Error {
    let line = record
        .and_then(|r| r.position())
        .or(e.position())
        .map_or(String::new(), |p| format!("line {}: ", p.line()));
    let what = match e.kind() {
        csv::ErrorKind::Io(io) if io.to_string() == ROW_TOO_LONG => {
            format!("a row longer than {MAX_MANIFEST_ROW_BYTES} bytes (or a quote never closed)")
        }
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
            format!("{len} cells, header has {expected_len}")
        }
        csv::ErrorKind::Deserialize { err, .. } => match err.field().map(|i| i as usize) {
            Some(i) => format!(
                "{} = '{}': {}",
                header.get(i).unwrap_or("?"),
                record.and_then(|r| r.get(i)).unwrap_or(""),
                err.kind()
            ),
            None => err.kind().to_string(),
        },
        _ => e.to_string(),
    };
    Error::decode(path, format!("{line}{what}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_folder_names_are_safe_or_made_so() {
        for ok in ["00003_left", "a.b-c_d", "x"] {
            assert!(is_frame_folder_name(ok), "{ok}");
            assert_eq!(frame_folder_name(ok), ok);
        }
        for bad in [
            "",
            ".hidden",
            "..",
            "a/b",
            "../up",
            "ü",
            "a b",
            "index.jsonl",
            "index.part-0-of-2.jsonl",
        ] {
            assert!(!is_frame_folder_name(bad), "{bad:?}");
        }
        assert!(!is_frame_folder_name(&"a".repeat(256)));
        assert!(is_frame_folder_name(&"a".repeat(255)));
        // Renaming keeps what is safe and replaces the rest, one '_' per character.
        assert_eq!(frame_folder_name("a/b ü"), "a_b__");
        assert!(is_frame_folder_name(&frame_folder_name("a/b ü")));
        // A leading '.' survives renaming: such a name stays refused, never made visible.
        assert!(!is_frame_folder_name(&frame_folder_name("../x")));
    }

    #[test]
    fn csv_manifest_resolves_paths_and_names_frames() {
        let dir = std::env::temp_dir().join(format!("viewsynth-batch-manifest-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("frames.csv");
        std::fs::write(&p, "rgb,depth,fx,fy,cx,cy,depth_scale\n# comment\na.png,a.png,525,525,319.5,239.5,5000\n/abs/b.png,b.npy,500,500,320,240,\n").unwrap();
        let f = load_manifest(&p).unwrap();
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].rgb, dir.join("a.png"));
        assert_eq!(f[1].rgb, PathBuf::from("/abs/b.png"));
        assert_eq!((f[0].depth_scale, f[1].depth_scale), (Some(5000.0), None));
        assert_eq!(f[0].name.as_deref(), Some("00000_a"));
        std::fs::write(&p, "rgb,depth,fx,fy,cx\nx,y,1,2,3\n").unwrap();
        assert!(load_manifest(&p).unwrap_err().to_string().contains("'cy'"));
        std::fs::write(&p, "rgb,depth,fx,fy,cx,cy\nx,y,1,2,3,abc\n").unwrap();
        let e = load_manifest(&p).unwrap_err().to_string();
        assert!(e.contains("line 2: cy = 'abc'"), "{e}");
        std::fs::write(&p, "rgb,depth,fx,fy,cx,cy\nx,y,1,2,3\n").unwrap();
        let e = load_manifest(&p).unwrap_err().to_string();
        assert!(e.contains("line 2: 5 cells, header has 6"), "{e}");
        // Quoted cells may hold the delimiter; a blank line and a comment are skipped.
        std::fs::write(
            &p,
            "rgb,depth,fx,fy,cx,cy,sun_bit_rotate,extra\n\n# c\n\"a,1.png\", b.png ,1,2,3,4,true,z\n",
        )
        .unwrap();
        let f = load_manifest(&p).unwrap();
        assert_eq!(
            (f[0].rgb.clone(), f[0].depth.clone()),
            (dir.join("a,1.png"), dir.join("b.png"))
        );
        assert!(f[0].sun_bit_rotate && f[0].cy == 4.0);
        let j = dir.join("frames.json");
        std::fs::write(&j, r#"[{"name":"same","rgb":"a","depth":"b","fx":1,"fy":1,"cx":0,"cy":0},{"name":"same","rgb":"c","depth":"d","fx":1,"fy":1,"cx":0,"cy":0}]"#).unwrap();
        assert!(load_manifest(&j).unwrap_err().to_string().contains("repeated"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Rows of `n` frames made on the fly, counting the bytes the parser has taken.
    struct Rows {
        head: Vec<u8>,
        next: usize,
        n: usize,
        row: Vec<u8>,
        taken: std::rc::Rc<std::cell::Cell<u64>>,
        /// After the rows: one endless cell (no newline, no end).
        endless: bool,
    }

    impl Read for Rows {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            if self.row.is_empty() {
                if !self.head.is_empty() {
                    self.row = std::mem::take(&mut self.head);
                } else if self.next < self.n {
                    self.row = format!("r{0}.png,d{0}.npy,{0},2,3,4\n", self.next).into_bytes();
                    self.next += 1;
                } else if self.endless {
                    self.row = vec![b'a'; 4096];
                } else {
                    return Ok(0);
                }
            }
            let k = buf.len().min(self.row.len());
            buf[..k].copy_from_slice(&self.row[..k]);
            self.row.drain(..k);
            self.taken.set(self.taken.get() + k as u64);
            Ok(k)
        }
    }

    fn rows(n: usize, endless: bool) -> (Rows, std::rc::Rc<std::cell::Cell<u64>>) {
        let taken = std::rc::Rc::new(std::cell::Cell::new(0));
        let r = Rows {
            head: b"rgb,depth,fx,fy,cx,cy\n".to_vec(),
            next: 0,
            n,
            row: Vec::new(),
            taken: taken.clone(),
            endless,
        };
        (r, taken)
    }

    #[test]
    fn csv_rows_are_streamed_and_a_row_without_end_is_refused_after_a_bounded_read() {
        // 10^5 rows parsed from a stream, one at a time, each into its frame.
        let (r, taken) = rows(100_000, false);
        let f = parse_csv(Path::new("m.csv"), r, [None; 4]).unwrap();
        assert_eq!(f.len(), 100_000);
        assert_eq!(
            (f[99_999].rgb.clone(), f[99_999].fx),
            (PathBuf::from("r99999.png"), 99_999.0)
        );
        assert!(taken.get() > 2_000_000, "{}", taken.get());
        // One endless row after 10 good ones: refused by its length, having read at most the
        // rows before it, one row's bound and the reader's buffer (twice: a refill in flight).
        let (r, taken) = rows(10, true);
        let e = parse_csv(Path::new("m.csv"), r, [None; 4]).unwrap_err().to_string();
        assert!(
            e.contains(&format!("longer than {MAX_MANIFEST_ROW_BYTES} bytes")),
            "{e}"
        );
        let bound = 400 + MAX_MANIFEST_ROW_BYTES + 2 * CSV_BUFFER as u64;
        assert!(taken.get() <= bound, "read {} bytes, bound {bound}", taken.get());
        // A quote never closed is one endless row too.
        let (mut r, _) = rows(3, false);
        r.head = b"rgb,depth,fx,fy,cx,cy\n\"".to_vec();
        r.endless = true;
        let e = parse_csv(Path::new("m.csv"), r, [None; 4]).unwrap_err().to_string();
        assert!(e.contains("longer than"), "{e}");
    }

    #[test]
    fn a_manifest_with_a_byte_order_mark_and_an_oversized_file_are_handled() {
        let dir = std::env::temp_dir().join(format!("viewsynth-batch-bom-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("frames.csv");
        std::fs::write(&p, "\u{feff}rgb,depth,fx,fy,cx,cy\na.png,a.npy,1,2,3,4\n").unwrap();
        assert_eq!(load_manifest(&p).unwrap()[0].cy, 4.0);
        let j = dir.join("frames.json");
        std::fs::write(
            &j,
            "\u{feff}[{\"rgb\":\"a\",\"depth\":\"b\",\"fx\":1,\"fy\":1,\"cx\":0,\"cy\":0}]",
        )
        .unwrap();
        assert_eq!(load_manifest(&j).unwrap().len(), 1);
        // Larger than the JSON cap: refused from its size, before a byte is parsed.
        let f = std::fs::File::create(&j).unwrap();
        f.set_len(MAX_JSON_MANIFEST_BYTES + 1).unwrap();
        let e = load_manifest(&j).unwrap_err().to_string();
        assert!(e.contains("frames.json"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
