//! File formats, byte by byte: decoding of PNG/JPEG/TIFF/..., EXR, NetPBM (PGM, PFM), raw
//! depth samples, NumPy `.npy`/`.npz`, and the encoder settings for writing them.

pub(crate) mod decode;
pub(crate) mod encoding;
pub(crate) mod exr;
pub(crate) mod grey_png;
pub(crate) mod netpbm;
pub(crate) mod npy;
pub(crate) mod npy_header;
pub(crate) mod npz;
pub(crate) mod pfm;
pub(crate) mod pgm;
pub(crate) mod raw_depth;
