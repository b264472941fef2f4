//! NumPy `.npy` arrays (format versions 1.0, 2.0, 3.0): strict reader, f32 writer.
//!
//! One reader, [`NpyStream`], for `.npy` files and `.npz` members alike: the header is read
//! and checked (its length against 1 MiB and the input, the element count against the pixel
//! budget, the input's length against the shape) before a byte of the payload is, and the
//! payload is decoded in chunks, never held whole. `npyz` was weighed and kept out: it
//! allocates the header length a file declares before reading it, accepts unknown and
//! duplicate dict keys, and multiplies the shape without an overflow check.

use std::io::{Read, Write};
use std::path::Path;

use super::npy_header::{dtype_of, parse_dict, parse_header, Header, NpyDtype};
use crate::error::{Error, Result};
use crate::io::files::atomic::atomic_write;
use crate::io::files::input::{max_pixels, open_regular};

const MAGIC: &[u8] = b"\x93NUMPY";

/// A loaded array, always in C (row-major) order whatever the file's `fortran_order`.
/// Values are widened to f64, which is exact for every supported dtype.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    /// Dimensions, outermost first (NumPy's `shape`).
    pub shape: Vec<usize>,
    /// Element type as stored in the file.
    pub dtype: NpyDtype,
    /// Values in C (row-major) order, widened to f64.
    pub data: Vec<f64>,
}

/// Reads an `.npy` file. The header must be a well-formed dict with exactly the keys
/// `descr`, `fortran_order` and `shape`; the payload must be exactly as long as it says. The
/// header is read and checked (element count against 4 x the pixel budget, the file's length
/// against the shape) before the payload is read, and nothing past it is read.
pub fn load_npy(path: &Path) -> Result<NpyArray> {
    read_npy(path, open_npy(path, max_pixels().saturating_mul(4))?)
}

/// Largest header accepted (NumPy writes well under 1 KiB; format 2.0 allows 4 GiB).
const MAX_HEADER: usize = 1 << 20;

/// An `.npy` file whose header was read and checked against `max_values` (from the pixel
/// budget) and the file's length; payload unread.
pub(crate) fn open_npy(path: &Path, max_values: u64) -> Result<NpyStream<std::fs::File>> {
    let (file, len) = open_regular(path)?;
    NpyStream::open(file, len, max_values).map_err(|m| Error::decode(path, m))
}

/// Reads exactly the payload the header declared.
pub(crate) fn read_npy(path: &Path, f: NpyStream<std::fs::File>) -> Result<NpyArray> {
    f.read().map_err(|m| Error::decode(path, m))
}

/// A `.npy` being read from a stream of known length (a file, or an `.npz` member as it is
/// inflated), its header read and checked; errors are messages for the caller to attach to
/// the file (and member) they name.
pub(crate) struct NpyStream<R> {
    reader: R,
    header: Header,
    need: usize,
}

impl<R: Read> NpyStream<R> {
    /// Reads the header of a `.npy` of exactly `len` bytes and checks its extent: no more than
    /// `max_values` elements, and exactly as many payload bytes as the shape needs.
    pub(crate) fn open(mut reader: R, len: u64, max_values: u64) -> std::result::Result<Self, String> {
        let (header, data_offset) = read_header(&mut reader, len).map_err(|m| format!("invalid NPY: {m}"))?;
        let need = payload_extent(&header, len - data_offset as u64, max_values)?;
        Ok(NpyStream { reader, header, need })
    }

    pub(crate) fn shape(&self) -> &[usize] {
        &self.header.shape
    }

    /// Decodes the payload chunk by chunk; the stream must end exactly where it does.
    pub(crate) fn read(mut self) -> std::result::Result<NpyArray, String> {
        let item = self.header.item_size;
        let count = self.need / item;
        let mut data = Vec::new();
        data.try_reserve_exact(count)
            .map_err(|_| format!("cannot allocate {count} values"))?;
        let mut chunk = vec![0u8; item * 8192];
        let mut left = self.need;
        while left > 0 {
            let n = left.min(chunk.len());
            read_all(&mut self.reader, &mut chunk[..n]).map_err(|m| format!("invalid NPY: {m}"))?;
            data.extend(chunk[..n].chunks_exact(item).map(self.header.decode));
            left -= n;
        }
        // One more byte: past the declared length is an error (and an archive member's
        // checksum is verified at its end).
        let mut extra = [0u8; 1];
        if self.reader.read(&mut extra).map_err(|e| e.to_string())? != 0 {
            return Err("invalid NPY: trailing bytes after the declared payload".into());
        }
        let data = if self.header.fortran_order {
            fortran_to_c(&self.header.shape, &data)
        } else {
            data
        };
        Ok(NpyArray {
            shape: self.header.shape,
            dtype: self.header.dtype,
            data,
        })
    }
}

/// The header dict's text of an input of `len` bytes, and where its payload starts. The
/// header's declared length is checked against 1 MiB and the input before it is allocated.
fn read_header_text(r: &mut impl Read, len: u64) -> std::result::Result<(String, usize), String> {
    // Magic and version (8 bytes), then the 2- or 4-byte header length they call for; a short
    // input gets header_extent's message.
    let mut head = Vec::with_capacity(12);
    r.by_ref().take(8).read_to_end(&mut head).map_err(|e| e.to_string())?;
    let len_bytes = if head.get(6..8) == Some(&[1, 0][..]) { 2 } else { 4 };
    r.by_ref()
        .take(len_bytes)
        .read_to_end(&mut head)
        .map_err(|e| e.to_string())?;
    let (prefix_len, header_len) = header_extent(&head)?;
    if header_len > MAX_HEADER {
        return Err(format!("header length {header_len} exceeds {MAX_HEADER} bytes"));
    }
    let data_offset = prefix_len + header_len;
    if data_offset as u64 > len {
        return Err(format!("header length {header_len} exceeds the file"));
    }
    head.resize(data_offset, 0);
    read_all(r, &mut head[prefix_len..])?;
    let text = std::str::from_utf8(&head[prefix_len..]).map_err(|_| "header is not UTF-8")?;
    let text = text.strip_suffix('\n').ok_or("header does not end with a newline")?;
    Ok((text.to_string(), data_offset))
}

/// The parsed header of an input of `len` bytes, and where its payload starts. The header's
/// declared length is checked against 1 MiB and the input before it is allocated.
fn read_header(r: &mut impl Read, len: u64) -> std::result::Result<(Header, usize), String> {
    let (text, data_offset) = read_header_text(r, len)?;
    Ok((parse_header(&text)?, data_offset))
}

/// The element type a `.npy` of `len` bytes declares, from its header alone: `None` for a
/// well-formed header of a type this reader does not decode (`|b1`, `<i8`, ...), which a
/// search for the first floating-point array passes over.
pub(crate) fn read_dtype(r: &mut impl Read, len: u64) -> std::result::Result<Option<NpyDtype>, String> {
    let (text, _) = read_header_text(r, len).map_err(|m| format!("invalid NPY: {m}"))?;
    let (descr, _, _) = parse_dict(&text).map_err(|m| format!("invalid NPY: {m}"))?;
    Ok(dtype_of(&descr).map(|(dtype, _, _)| dtype))
}

fn read_all(r: &mut impl Read, buf: &mut [u8]) -> std::result::Result<(), String> {
    r.read_exact(buf).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => "truncated: the data ends early".to_string(),
        _ => e.to_string(),
    })
}

/// Payload bytes the header declares, checked before anything is read from it: no overflow,
/// at most `max_values` elements, and exactly `have` bytes present. Malformed extents are
/// "invalid NPY"; the budget's refusal says which option raises it.
fn payload_extent(h: &Header, have: u64, max_values: u64) -> std::result::Result<usize, String> {
    let overflow = || format!("invalid NPY: shape {:?} overflows", h.shape);
    let count = h
        .shape
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .ok_or_else(overflow)?;
    let need = count.checked_mul(h.item_size).ok_or_else(overflow)?;
    if count as u64 > max_values {
        return Err(format!(
            "shape {:?} = {count} values exceeds the pixel budget ({} pixels; --max-pixels; refused before reading the values)",
            h.shape,
            max_pixels()
        ));
    }
    if have != need as u64 {
        let what = if have < need as u64 {
            "truncated"
        } else {
            "trailing bytes"
        };
        return Err(format!(
            "invalid NPY: {what}: header says shape {:?} of {} = {need} data bytes, file has {have}",
            h.shape, h.descr,
        ));
    }
    Ok(need)
}

/// (bytes before the header dict, its length) from the file's first bytes.
fn header_extent(start: &[u8]) -> std::result::Result<(usize, usize), String> {
    let rest = start.strip_prefix(MAGIC).ok_or("missing \\x93NUMPY magic")?;
    let len_bytes = match rest.get(..2) {
        Some([1, 0]) => 2,
        Some([2, 0] | [3, 0]) => 4,
        Some(v) => return Err(format!("unsupported format version {v:?}")),
        None => return Err("file ends inside the header".into()),
    };
    let field = rest.get(2..2 + len_bytes).ok_or("file ends inside the header")?;
    let len = field.iter().rev().fold(0usize, |acc, &b| (acc << 8) | usize::from(b));
    Ok((MAGIC.len() + 2 + len_bytes, len))
}

/// Writes `data` as `<f4` in C order with the given shape, NPY format 1.0.
pub fn save_npy_f32(path: &Path, shape: &[usize], data: &[f32]) -> Result<()> {
    check_shape(path, shape, data)?;
    atomic_write(path, |out| encode_npy_f32(path, out, shape, data))
}

fn check_shape(path: &Path, shape: &[usize], data: &[f32]) -> Result<()> {
    let count = shape.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d));
    if count != Some(data.len()) {
        return Err(Error::SizeMismatch {
            message: format!(
                "{}: shape {shape:?} does not hold {} values",
                path.display(),
                data.len()
            ),
        });
    }
    Ok(())
}

/// Encodes [`save_npy_f32`]'s file into `out`; errors name `path`.
pub(crate) fn encode_npy_f32(
    path: &Path,
    out: &mut std::io::BufWriter<std::fs::File>,
    shape: &[usize],
    data: &[f32],
) -> Result<()> {
    check_shape(path, shape, data)?;
    let header =
        format_header("<f4", shape).ok_or_else(|| Error::encode(path, "NPY header longer than 65535 bytes"))?;
    out.write_all(&header).map_err(|e| Error::io(path, e))?;
    for v in data {
        out.write_all(&v.to_le_bytes()).map_err(|e| Error::io(path, e))?;
    }
    Ok(())
}

/// Magic, version, length and dict text padded so the payload starts 64-byte aligned.
fn format_header(descr: &str, shape: &[usize]) -> Option<Vec<u8>> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_text = match dims.as_slice() {
        [one] => format!("({one},)"),
        _ => format!("({})", dims.join(", ")),
    };
    let mut dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape_text}, }}");
    let unpadded = MAGIC.len() + 2 + 2 + dict.len() + 1;
    dict.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    dict.push('\n');
    let len = u16::try_from(dict.len()).ok()?;
    let mut out = Vec::with_capacity(10 + dict.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&len.to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    Some(out)
}

/// Reorders column-major data (first index fastest) to row-major.
fn fortran_to_c(shape: &[usize], data: &[f64]) -> Vec<f64> {
    if shape.len() < 2 {
        return data.to_vec();
    }
    // Strides fit: their product is the element count, already checked.
    let mut strides = vec![1usize; shape.len()];
    for k in 1..shape.len() {
        strides[k] = strides[k - 1] * shape[k - 1];
    }
    let mut index = vec![0usize; shape.len()];
    let mut out = Vec::with_capacity(data.len());
    for _ in 0..data.len() {
        let offset: usize = index.iter().zip(&strides).map(|(i, s)| i * s).sum();
        out.push(data.get(offset).copied().unwrap_or(f64::NAN));
        for k in (0..shape.len()).rev() {
            index[k] += 1;
            if index[k] < shape[k] {
                break;
            }
            index[k] = 0;
        }
    }
    out
}

/// Builds an NPY v1.0 file by hand from raw dict text and payload, for tests.
#[cfg(test)]
pub(crate) fn build_npy(dict: &str, payload: &[u8]) -> Vec<u8> {
    let mut text = dict.to_string();
    while !(10 + text.len() + 1).is_multiple_of(64) {
        text.push(' ');
    }
    text.push('\n');
    let mut out = MAGIC.to_vec();
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(text.len() as u16).to_le_bytes());
    out.extend_from_slice(text.as_bytes());
    out.extend_from_slice(payload);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn f32_round_trip_and_header_layout() {
        let dir = scratch_dir("npy-f32");
        let path = dir.join("a.npy");
        let data: Vec<f32> = (0..6).map(|i| i as f32 * 0.5 - 1.0).collect();
        save_npy_f32(&path, &[2, 3], &data).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let header_len = usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
        assert_eq!((10 + header_len) % 64, 0);
        assert_eq!(bytes[9 + header_len], b'\n');
        let text = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(text.starts_with("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }"));
        let arr = load_npy(&path).unwrap();
        assert_eq!(arr.shape, vec![2, 3]);
        assert_eq!(arr.dtype, NpyDtype::F32);
        assert_eq!(arr.data, data.iter().map(|&v| f64::from(v)).collect::<Vec<_>>());
    }

    #[test]
    fn one_d_and_scalar_shapes() {
        let dir = scratch_dir("npy-shapes");
        let path = dir.join("a.npy");
        save_npy_f32(&path, &[3], &[1.0, 2.0, 3.0]).unwrap();
        assert_eq!(load_npy(&path).unwrap().shape, vec![3]);
        save_npy_f32(&path, &[], &[4.0]).unwrap();
        let arr = load_npy(&path).unwrap();
        assert_eq!((arr.shape.len(), arr.data.as_slice()), (0, &[4.0][..]));
        assert!(save_npy_f32(&path, &[2, 2], &[1.0]).is_err());
    }

    #[test]
    fn f64_big_endian_u16_and_python2_header() {
        let dir = scratch_dir("npy-dtypes");
        let payload: Vec<u8> = [1.5f64, -2.0].iter().flat_map(|v| v.to_be_bytes()).collect();
        let p = write(
            &dir,
            "be.npy",
            &build_npy("{'descr': '>f8', 'fortran_order': False, 'shape': (2,), }", &payload),
        );
        assert_eq!(load_npy(&p).unwrap().data, vec![1.5, -2.0]);

        let payload: Vec<u8> = [1u16, 65535].iter().flat_map(|v| v.to_le_bytes()).collect();
        let p = write(
            &dir,
            "u2.npy",
            &build_npy(
                "{\"shape\": (1L, 2L), \"descr\": \"<u2\", \"fortran_order\": False}",
                &payload,
            ),
        );
        let arr = load_npy(&p).unwrap();
        assert_eq!(
            (arr.dtype, arr.shape, arr.data),
            (NpyDtype::U16, vec![1, 2], vec![1.0, 65535.0])
        );
    }

    #[test]
    fn fortran_order_is_reordered_to_c() {
        let dir = scratch_dir("npy-fortran");
        // C-order [[0, 1, 2], [3, 4, 5]] stored column-major: 0 3 1 4 2 5.
        let payload: Vec<u8> = [0f32, 3.0, 1.0, 4.0, 2.0, 5.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let p = write(
            &dir,
            "f.npy",
            &build_npy("{'descr': '<f4', 'fortran_order': True, 'shape': (2, 3), }", &payload),
        );
        assert_eq!(load_npy(&p).unwrap().data, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        let shape = [2, 3, 2];
        let f: Vec<f64> = (0..12).map(f64::from).collect();
        let c = fortran_to_c(&shape, &f);
        // Element (i, j, k) is at i + 2j + 6k in Fortran order.
        assert_eq!(c[3 * 2 + 2 + 1], f[1 + 2 + 6]);
    }

    #[test]
    fn truncated_and_trailing_payloads_are_refused() {
        let dir = scratch_dir("npy-trunc");
        let dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4), }";
        let p = write(&dir, "short.npy", &build_npy(dict, &[0u8; 60]));
        let err = load_npy(&p).unwrap_err();
        assert!(matches!(err, Error::Decode { .. }));
        let msg = err.to_string();
        assert!(msg.contains("short.npy") && msg.contains("truncated"), "{msg}");
        let p = write(&dir, "long.npy", &build_npy(dict, &[0u8; 65]));
        assert!(load_npy(&p).is_err());
        // Header length pointing past the end of the file.
        let p = write(&dir, "cut.npy", &build_npy(dict, &[])[..30]);
        assert!(matches!(load_npy(&p), Err(Error::Decode { .. })));
        // A huge claimed shape must fail on size, not allocate.
        let big = "{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999, 99999999999), }";
        let p = write(&dir, "big.npy", &build_npy(big, &[0u8; 8]));
        assert!(matches!(load_npy(&p), Err(Error::Decode { .. })));
    }

    #[test]
    fn malformed_headers_are_refused() {
        let dir = scratch_dir("npy-bad");
        let cases = [
            "{'descr': '<i4', 'fortran_order': False, 'shape': (1,), }",
            "{'descr': '<f4', 'fortran_order': False, }",
            "{'descr': '<f4', 'fortran_order': 0, 'shape': (1,), }",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (1,), 'x': 1}",
            "{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (1,)}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (1), }",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (-1,), }",
            "{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (1,), }",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (1,), } junk",
        ];
        for dict in cases {
            let p = write(&dir, "bad.npy", &build_npy(dict, &[0u8; 4]));
            assert!(matches!(load_npy(&p), Err(Error::Decode { .. })), "accepted {dict}");
        }
        let p = write(&dir, "magic.npy", b"\x93NUMPX\x01\x00\x00\x00");
        assert!(load_npy(&p).is_err());
        let err = load_npy(&dir.join("missing.npy")).unwrap_err();
        assert!(err.to_string().contains("missing.npy"));
    }
}
