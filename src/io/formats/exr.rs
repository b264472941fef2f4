//! OpenEXR through the `exr` crate: one depth channel in, f32 channels out.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom};
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, FlatSamples, Image, Layer, LayerAttributes, MetaData, ReadChannels, ReadLayers, SmallVec,
    WritableImage,
};

use crate::error::{Error, Result};
use crate::io::files::input::{check_file_len, max_pixels, open_regular};
use crate::io::formats::raw_depth::{RawDepth, RawSamples};
use crate::io::image::types::{decode_dims, sample_count};

/// Width and height of a single-layer EXR from its header alone.
pub(crate) fn exr_dimensions(path: &Path) -> Result<(u32, u32)> {
    let (file, _) = open_regular(path)?;
    let meta = MetaData::read_from_buffered(BufReader::new(file), false).map_err(|e| exr_error(path, e))?;
    match meta.headers.as_slice() {
        [h] => {
            check_sampling(path, h)?;
            decode_dims(path, h.layer_size.width() as u64, h.layer_size.height() as u64)
        }
        hs => Err(Error::decode(
            path,
            format!("EXR has {} layers; expected exactly one", hs.len()),
        )),
    }
}

/// Refuses a header with a subsampled channel (x or y sampling other than 1, e.g. chroma
/// subsampling), naming the channel: its sample counts and offset table differ from a flat
/// image's, which would otherwise read as a corrupt file.
fn check_sampling(path: &Path, header: &exr::meta::header::Header) -> Result<()> {
    match header
        .channels
        .list
        .iter()
        .find(|c| c.sampling != exr::math::Vec2(1, 1))
    {
        Some(c) => Err(Error::decode(
            path,
            format!(
                "EXR channel {} is subsampled ({} x {}): subsampled channels are not supported; \
                 write every channel at full resolution",
                c.name, c.sampling.0, c.sampling.1
            ),
        )),
        None => Ok(()),
    }
}

/// Refuses an EXR with a subsampled channel, from its headers alone (colour inputs, which the
/// `image` crate decodes).
pub(crate) fn check_exr_sampling(path: &Path) -> Result<()> {
    let (file, _) = open_regular(path)?;
    let meta = MetaData::read_from_buffered(BufReader::new(file), false).map_err(|e| exr_error(path, e))?;
    meta.headers.iter().try_for_each(|h| check_sampling(path, h))
}

/// Reads the depth channel of a single-layer, flat EXR: "Z", else "depth" (any case), else
/// "Y", else "R", else the only channel. f16 is widened to f32; u32 stays integer.
pub(crate) fn read_depth_channel(path: &Path) -> Result<RawDepth> {
    // Headers first, so the size checks happen before the body is read or pixels allocated.
    let (file, len) = open_regular(path)?;
    let mut counted = Counted {
        inner: BufReader::new(file),
        n: 0,
    };
    let meta = MetaData::read_from_buffered(&mut counted, false).map_err(|e| exr_error(path, e))?;
    let header = match meta.headers.as_slice() {
        [h] => h,
        hs => {
            return Err(Error::decode(
                path,
                format!("EXR has {} layers; expected exactly one", hs.len()),
            ))
        }
    };
    if header.deep {
        return Err(Error::decode(path, "deep EXR data is not supported"));
    }
    check_sampling(path, header)?;
    let (width, height) = decode_dims(
        path,
        header.layer_size.width() as u64,
        header.layer_size.height() as u64,
    )?;
    // Uncompressed f32 (4 bytes a sample, 4/3 with mip levels) fits twice over: a longer file
    // is not this image, and is not read.
    let samples = u64::from(width) * u64::from(height) * header.channels.list.len() as u64;
    check_file_len(
        path,
        len,
        samples.saturating_mul(8).saturating_add(1 << 20),
        "its header's image",
    )?;
    let channels_budget = max_pixels().saturating_mul(4);
    if samples > channels_budget {
        return Err(Error::decode(
            path,
            format!(
                "{width}x{height} with {} channels = {samples} samples exceeds 4 x the pixel budget ({channels_budget}; --max-pixels)",
                header.channels.list.len()
            ),
        ));
    }
    check_offset_table(path, &meta, &mut counted, len)?;
    let (file, _) = open_regular(path)?;

    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(BufReader::new(file))
        .map_err(|e| exr_error(path, e))?;
    let layer = match image.layer_data.into_iter().next() {
        Some(layer) => layer,
        None => return Err(Error::decode(path, "EXR has no layers")),
    };
    let mut channels = layer.channel_data.list.into_vec();
    let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
    let index = choose_channel(&names).ok_or_else(|| {
        Error::decode(
            path,
            format!(
                "cannot tell which EXR channel is depth among [{}]; expected one named \
                 Z, depth, Y or R, or a single channel",
                names.join(", ")
            ),
        )
    })?;
    let channel = channels.swap_remove(index);
    let samples = match channel.sample_data {
        FlatSamples::F16(v) => RawSamples::F32(v.into_iter().map(|s| s.to_f32()).collect()),
        FlatSamples::F32(v) => RawSamples::F32(v),
        FlatSamples::U32(v) => RawSamples::U32(v),
    };
    let expected = sample_count(width, height, 1);
    if expected != Some(samples.len()) {
        return Err(Error::decode(
            path,
            format!(
                "EXR channel {} has {} samples for a {width}x{height} image (subsampled?)",
                names[index],
                samples.len()
            ),
        ));
    }
    Ok(RawDepth { width, height, samples })
}

/// Counts the bytes read through it: where the headers end, the offset table starts.
struct Counted<R> {
    inner: R,
    n: u64,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.n += n as u64;
        Ok(n)
    }
}

/// Refuses a chunk offset table that does not point each entry at its own chunk. The `exr`
/// crate reads the chunks the table points at (in table order, without pedantic checks), so a
/// table pointing every entry at line 0 decoded line 0 again and again and left the rest of
/// the image 0 -- a few percent valid depth, no error. Each entry (in increasing-y block order,
/// as the crate's reader indexes it) must lie inside the file after the table, and the chunk
/// there must name that block: its first scan line, or its tile and level.
fn check_offset_table(path: &Path, meta: &MetaData, counted: &mut Counted<impl Read>, len: u64) -> Result<()> {
    let header = &meta.headers[0];
    let bad = |what: String| Error::decode(path, format!("corrupt EXR offset table: {what}"));
    let count = header.chunk_count as u64;
    let table_end = counted.n.saturating_add(count.saturating_mul(8));
    if table_end > len {
        return Err(bad(format!("{count} entries do not fit in the file")));
    }
    let mut table = vec![0u8; count as usize * 8];
    counted.read_exact(&mut table).map_err(|e| Error::io(path, e))?;
    // Multi-part files prefix each chunk with its part number.
    let prefix = if meta.requirements.has_multiple_layers { 4 } else { 0 };
    let scan_lines = match header.blocks {
        exr::meta::BlockDescription::ScanLines => Some(header.compression.scan_lines_per_block() as i64),
        exr::meta::BlockDescription::Tiles(_) => None,
    };
    let (mut file, _) = open_regular(path)?;
    let mut seen = std::collections::HashSet::with_capacity(count as usize);
    for (i, (entry, block)) in table
        .chunks_exact(8)
        .zip(header.blocks_increasing_y_order())
        .enumerate()
    {
        let offset = u64::from_le_bytes(entry.try_into().expect("8 bytes"));
        let need = prefix + if scan_lines.is_some() { 4 } else { 16 };
        if offset < table_end || offset.saturating_add(need) > len || !seen.insert(offset) {
            return Err(bad(format!(
                "entry {i} = {offset} is outside the chunks ({table_end}..{len}) or repeated"
            )));
        }
        let mut head = [0u8; 20];
        let head = &mut head[..need as usize];
        file.seek(SeekFrom::Start(offset)).map_err(|e| Error::io(path, e))?;
        file.read_exact(head).map_err(|e| Error::io(path, e))?;
        let ints: Vec<i64> = head[prefix as usize..]
            .chunks_exact(4)
            .map(|b| i64::from(i32::from_le_bytes(b.try_into().expect("4 bytes"))))
            .collect();
        let loc = block.location;
        let expected: Vec<i64> = match scan_lines {
            Some(lines) => vec![header.own_attributes.layer_position.y() as i64 + loc.tile_index.y() as i64 * lines],
            None => [
                loc.tile_index.x(),
                loc.tile_index.y(),
                loc.level_index.x(),
                loc.level_index.y(),
            ]
            .iter()
            .map(|&v| v as i64)
            .collect(),
        };
        if ints != expected {
            return Err(bad(format!(
                "entry {i} points at the chunk of block {ints:?}, not {expected:?}"
            )));
        }
    }
    Ok(())
}

fn choose_channel(names: &[String]) -> Option<usize> {
    let find = |pred: &dyn Fn(&str) -> bool| names.iter().position(|n| pred(n));
    find(&|n| n == "Z")
        .or_else(|| find(&|n| n.eq_ignore_ascii_case("depth")))
        .or_else(|| find(&|n| n == "Y"))
        .or_else(|| find(&|n| n == "R"))
        .or(if names.len() == 1 { Some(0) } else { None })
}

/// Writes one scan-line layer of full-resolution f32 channels with the given compression.
/// Each channel must hold `width * height` samples, rows top-down.
pub(crate) fn write_f32_channels(
    path: &Path,
    out: &mut BufWriter<File>,
    width: u32,
    height: u32,
    channels: Vec<(&str, Vec<f32>)>,
    compression: crate::io::ExrCompression,
) -> Result<()> {
    let planes: Vec<(&str, &[f32])> = channels.iter().map(|(name, v)| (*name, v.as_slice())).collect();
    write_f32_planes(path, out, width, height, &planes, compression)
}

/// [`write_f32_channels`] from borrowed samples.
///
/// ZIP (the default) is compressed here, block by block, with libdeflate at its fastest level
/// (the `exr` crate's own ZIP runs miniz_oxide at level 4: about 2.5x the CPU for files ~5 %
/// smaller), in tasks on the rayon pool ([`zip_blocks`]), straight from the caller's samples
/// (no copy of the image); the blocks, header and offset table are the `exr` crate's, and any
/// OpenEXR reader decodes the file. Other compressions go through the `exr` crate as they are,
/// which takes its own copy of the samples.
pub(crate) fn write_f32_planes(
    path: &Path,
    out: &mut BufWriter<File>,
    width: u32,
    height: u32,
    channels: &[(&str, &[f32])],
    compression: crate::io::ExrCompression,
) -> Result<()> {
    let zip = compression == crate::io::ExrCompression::Zip;
    // With ZIP the layer only names the channels (its header); the samples stay the caller's.
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|&(name, data)| AnyChannel::new(name, FlatSamples::F32(if zip { Vec::new() } else { data.to_vec() })))
        .collect();
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        compression.exr_encoding(),
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);
    let result = if compression == crate::io::ExrCompression::Zip {
        let headers = image.write().infer_meta_data();
        // In the header's order: AnyChannels::sort orders the channels by name.
        let mut sorted = channels.to_vec();
        sorted.sort_by(|a, b| a.0.cmp(b.0));
        let planes: Vec<&[f32]> = sorted.iter().map(|&(_, data)| data).collect();
        let lines = exr::prelude::Compression::ZIP16.scan_lines_per_block();
        let blocks = zip_blocks(&planes, width as usize, height as usize, lines);
        exr::block::write(out, headers, true, |_, writer| {
            use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
            use exr::block::writer::ChunksWriter;
            for (i, compressed_pixels_le) in blocks.into_iter().enumerate() {
                let y_coordinate =
                    i32::try_from(i * lines).map_err(|_| exr::error::Error::Invalid("image height".into()))?;
                let block = CompressedScanLineBlock {
                    y_coordinate,
                    compressed_pixels_le,
                };
                writer.write_chunk(
                    i,
                    Chunk {
                        layer_index: 0,
                        compressed_block: CompressedBlock::ScanLine(block),
                    },
                )?;
            }
            Ok(())
        })
    } else {
        image.write().to_buffered(out)
    };
    result.map_err(|e| match e {
        exr::error::Error::Io(io) => Error::io(path, io),
        other => Error::encode(path, other.to_string()),
    })
}

/// Blocks of 16 lines one task of [`zip_blocks`] compresses in turn (4: ~160 KB of f32 VGA
/// rows, ~0.5 ms here): small enough to spread a VGA image's 30 blocks over the cores and over
/// the other files being encoded beside it, large enough that splitting costs nothing.
const BLOCKS_PER_TASK: usize = 4;

/// The ZIP chunks of a scan-line image: per block of `lines` rows, each row's channels in
/// turn (little-endian f32), byte-split into even and odd bytes, delta-coded and deflated
/// (zlib) -- OpenEXR's ZIP -- or the raw bytes where deflate would not make them smaller.
/// Tasks of [`BLOCKS_PER_TASK`] blocks run on the rayon pool, beside whatever else it runs
/// (a view's PNGs: see `FileSet::write_all`).
fn zip_blocks(planes: &[&[f32]], width: usize, height: usize, lines: usize) -> Vec<Vec<u8>> {
    let mut blocks = vec![Vec::new(); height.div_ceil(lines)];
    let image = ZipImage {
        planes,
        width,
        height,
        lines,
    };
    image.compress(&mut blocks, 0);
    blocks
}

/// What every task of [`zip_blocks`] reads.
#[derive(Clone, Copy)]
struct ZipImage<'a> {
    planes: &'a [&'a [f32]],
    width: usize,
    height: usize,
    lines: usize,
}

/// Largest block buffers a pool thread keeps between files (a block of 16 rows of 16,384 f32).
const KEEP_SCRATCH_BYTES: usize = 1 << 20;

thread_local! {
    /// Each pool thread's compressor and buffers, kept between blocks and files (a new
    /// libdeflate compressor allocates its hash tables each time).
    static ZIP_SCRATCH: std::cell::RefCell<Option<ZipScratch>> = const { std::cell::RefCell::new(None) };
}

struct ZipScratch {
    deflater: libdeflater::Compressor,
    raw: Vec<u8>,
    predicted: Vec<u8>,
    deflated: Vec<u8>,
}

impl ZipImage<'_> {
    /// Compresses blocks `first..first + out.len()` into `out`, splitting in halves on the pool.
    fn compress(self, out: &mut [Vec<u8>], first: usize) {
        if out.len() > BLOCKS_PER_TASK {
            let half = out.len() / 2;
            let (a, b) = out.split_at_mut(half);
            rayon_core::join(|| self.compress(a, first), || self.compress(b, first + half));
            return;
        }
        ZIP_SCRATCH.with(|cell| {
            let mut cell = cell.borrow_mut();
            let scratch = cell.get_or_insert_with(|| ZipScratch {
                // Level 1: libdeflate's fastest that compresses (0 only stores).
                deflater: libdeflater::Compressor::new(
                    libdeflater::CompressionLvl::new(1).expect("libdeflate has level 1"),
                ),
                raw: Vec::new(),
                predicted: Vec::new(),
                deflated: Vec::new(),
            });
            for (i, block) in out.iter_mut().enumerate() {
                *block = self.block(first + i, scratch);
            }
            // Kept for the next file unless a huge image grew them (a long-lived process).
            if scratch.raw.capacity() > KEEP_SCRATCH_BYTES {
                *cell = None;
            }
        });
    }

    fn block(&self, b: usize, s: &mut ZipScratch) -> Vec<u8> {
        let rows = b * self.lines..((b + 1) * self.lines).min(self.height);
        s.raw.clear();
        for y in rows {
            for plane in self.planes {
                extend_le(&mut s.raw, &plane[y * self.width..(y + 1) * self.width]);
            }
        }
        zip_predict(&s.raw, &mut s.predicted);
        s.deflated.resize(s.deflater.zlib_compress_bound(s.predicted.len()), 0);
        match s.deflater.zlib_compress(&s.predicted, &mut s.deflated) {
            Ok(n) if n < s.raw.len() => s.deflated[..n].to_vec(),
            _ => s.raw.clone(),
        }
    }
}

/// Appends `v` as little-endian f32 bytes: one copy on a little-endian machine.
fn extend_le(out: &mut Vec<u8>, v: &[f32]) {
    if cfg!(target_endian = "little") {
        out.extend_from_slice(bytemuck::cast_slice(v));
    } else {
        for x in v {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
}

/// OpenEXR's ZIP predictor: the even bytes then the odd bytes, each byte stored as its
/// difference from the previous one plus 128 (mod 256).
fn zip_predict(raw: &[u8], out: &mut Vec<u8>) {
    let n = raw.len();
    let half = n.div_ceil(2);
    out.clear();
    out.resize(n, 0);
    let (even, odd) = out.split_at_mut(half);
    for (i, pair) in raw.chunks_exact(2).enumerate() {
        even[i] = pair[0];
        odd[i] = pair[1];
    }
    if n % 2 == 1 {
        even[half - 1] = raw[n - 1];
    }
    let mut prev = out.first().copied().unwrap_or(0);
    for b in out.iter_mut().skip(1) {
        let cur = *b;
        *b = cur.wrapping_sub(prev).wrapping_add(128);
        prev = cur;
    }
}

fn exr_error(path: &Path, e: exr::error::Error) -> Error {
    Error::decode(path, format!("invalid EXR: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    /// A subsampled channel (x and y sampling 2, as chroma subsampling writes) is named as
    /// unsupported subsampling, for depth and colour alike (it read as a corrupt offset table).
    #[test]
    fn a_subsampled_channel_is_named_as_unsupported() {
        let dir = crate::io::test_util::scratch_dir("exr-subsampled");
        let (depth, rgb) = (dir.join("depth.exr"), dir.join("rgb.exr"));
        crate::io::save_depth_exr(&depth, &crate::io::DepthMap::new(4, 4, vec![1.5; 16]).unwrap()).unwrap();
        crate::io::save_rgb(&rgb, &crate::io::RgbImage::new(4, 4, vec![9; 48]).unwrap()).unwrap();
        for path in [&depth, &rgb] {
            // The channel list: "chlist", its size, then per channel a name, the pixel type (4),
            // pLinear and 3 reserved bytes, then x and y sampling (4 each): the first set to 2.
            let mut bytes = std::fs::read(path).unwrap();
            let at = bytes.windows(7).position(|w| w == b"chlist\0").unwrap() + 7 + 4;
            let name_end = at + bytes[at..].iter().position(|&b| b == 0).unwrap() + 1;
            let sampling = name_end + 4 + 4;
            bytes[sampling..sampling + 8].copy_from_slice(&[2, 0, 0, 0, 2, 0, 0, 0]);
            std::fs::write(path, &bytes).unwrap();
        }
        let e = read_depth_channel(&depth).unwrap_err().to_string();
        assert!(
            e.contains("depth.exr") && e.contains("is subsampled (2 x 2)") && !e.contains("corrupt"),
            "{e}"
        );
        let e = crate::io::load_rgb(&rgb).unwrap_err().to_string();
        assert!(e.contains("rgb.exr") && e.contains("is subsampled (2 x 2)"), "{e}");
    }

    #[test]
    fn channel_choice_priority() {
        assert_eq!(choose_channel(&names(&["B", "G", "R", "Z"])), Some(3));
        assert_eq!(choose_channel(&names(&["B", "Depth", "R"])), Some(1));
        assert_eq!(choose_channel(&names(&["R", "Y"])), Some(1));
        assert_eq!(choose_channel(&names(&["B", "G", "R"])), Some(2));
        assert_eq!(choose_channel(&names(&["disparity"])), Some(0));
        assert_eq!(choose_channel(&names(&["a", "b"])), None);
    }

    /// The ZIP files written here decode (through the `exr` crate's own ZIP reader and
    /// through `image`'s) to the samples written, bit for bit: sizes that are not a multiple of
    /// the 16-line block, several channels (written in name order), values that compress and
    /// blocks of noise that do not (stored raw, as OpenEXR does).
    #[test]
    fn zip_blocks_decode_bit_exact_through_other_readers() {
        let dir = crate::io::test_util::scratch_dir("exr-zip");
        let (w, h) = (37u32, 53u32);
        let mut state = 0x9e37_79b9u32;
        let mut noise = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            f32::from_bits(state & 0x7f7f_ffff)
        };
        // Smooth rows above, noise below: both kinds of block in one file.
        let z: Vec<f32> = (0..w * h)
            .map(|i| {
                if i < w * 20 {
                    1.0 + (i % w) as f32 * 0.01
                } else {
                    noise()
                }
            })
            .collect();
        let r: Vec<f32> = (0..w * h).map(|i| (i % 7) as f32 / 7.0).collect();
        let path = dir.join("zip.exr");
        let file = File::create(&path).unwrap();
        let mut out = BufWriter::new(file);
        let channels = vec![("Z", z.clone()), ("R", r.clone()), ("G", r.clone()), ("B", r.clone())];
        write_f32_channels(&path, &mut out, w, h, channels, crate::io::ExrCompression::Zip).unwrap();
        drop(out);
        let image = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
        let layer = &image.layer_data[0];
        assert_eq!(layer.encoding.compression, exr::prelude::Compression::ZIP16);
        let samples = |name: &str| -> Vec<f32> {
            let c = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name.to_string() == name)
                .unwrap();
            match &c.sample_data {
                FlatSamples::F32(v) => v.clone(),
                other => panic!("{other:?}"),
            }
        };
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&samples("Z")), bits(&z));
        assert_eq!(bits(&samples("R")), bits(&r));
        let depth = read_depth_channel(&path).unwrap();
        match depth.samples {
            RawSamples::F32(v) => assert_eq!(bits(&v), bits(&z)),
            _ => panic!("not f32"),
        }
        // The smooth part compresses: the file is well under the raw size.
        let raw = (w * h * 4 * 4) as u64;
        let len = std::fs::metadata(&path).unwrap().len();
        assert!(len < raw, "{len} >= {raw}");
        let decoded = image::open(&path).unwrap().into_rgba32f();
        assert_eq!(decoded.get_pixel(3, 1)[0].to_bits(), r[w as usize + 3].to_bits());
        assert_eq!(decoded.get_pixel(3, 1)[2].to_bits(), r[w as usize + 3].to_bits());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_zip_predictor_is_openexrs() {
        let mut out = Vec::new();
        zip_predict(&[10, 200, 12, 190, 15], &mut out);
        // Even bytes 10, 12, 15 then odd 200, 190; each the difference from the one before + 128.
        assert_eq!(out, vec![10, 130, 131, 57, 118]);
    }
}
