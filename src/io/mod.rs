//! Image, depth and mask I/O.
