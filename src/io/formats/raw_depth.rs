//! Depth samples as a file stores them, before conversion to metres: what the format readers
//! (EXR, PFM, PGM, PNG, NPY) hand to `depth.rs`. Kept apart so the readers do not depend on the
//! dispatcher that calls them.

/// Stored samples before conversion to metres, rows top-down.
#[derive(Debug)]
pub(crate) enum RawSamples {
    U8(Vec<u8>),
    U16(Vec<u16>),
    U32(Vec<u32>),
    F32(Vec<f32>),
    F64(Vec<f64>),
}

impl RawSamples {
    pub(crate) fn len(&self) -> usize {
        match self {
            RawSamples::U8(v) => v.len(),
            RawSamples::U16(v) => v.len(),
            RawSamples::U32(v) => v.len(),
            RawSamples::F32(v) => v.len(),
            RawSamples::F64(v) => v.len(),
        }
    }
}

#[derive(Debug)]
pub(crate) struct RawDepth {
    pub width: u32,
    pub height: u32,
    pub samples: RawSamples,
}
