//! Tokenizer for Netpbm-style text headers (PGM, PFM).

use std::str::FromStr;

/// Width and height from a PGM/PFM header (magic, width, height), checked against the limits
/// and the pixel budget; the rest is validated when the file is loaded.
pub(crate) fn netpbm_dimensions(path: &std::path::Path) -> crate::Result<(u32, u32)> {
    let (mut file, len) = crate::io::files::input::open_regular(path)?;
    let prefix = crate::io::files::input::read_prefix(path, &mut file, len, NETPBM_HEADER_CAP)?;
    let mut header = HeaderReader::new(&prefix);
    let bad = |msg: String| crate::Error::decode(path, format!("invalid header: {msg}"));
    header.token().ok_or_else(|| bad("empty file".into()))?;
    let width: u64 = header.number("width").map_err(bad)?;
    let height: u64 = header.number("height").map_err(bad)?;
    crate::io::image::types::decode_dims(path, width, height)
}

/// Bytes read for a Netpbm/PFM text header (comments included) before the raster.
pub(crate) const NETPBM_HEADER_CAP: usize = 64 * 1024;

pub(crate) struct HeaderReader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> HeaderReader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, pos: 0 }
    }

    /// Next token, skipping whitespace and `#` comments (which run to the end of the line).
    pub(crate) fn token(&mut self) -> Option<&'a [u8]> {
        loop {
            match self.bytes.get(self.pos)? {
                c if c.is_ascii_whitespace() => self.pos += 1,
                b'#' => {
                    while self.bytes.get(self.pos).is_some_and(|&c| c != b'\n' && c != b'\r') {
                        self.pos += 1;
                    }
                }
                _ => break,
            }
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|&c| !c.is_ascii_whitespace() && c != b'#')
        {
            self.pos += 1;
        }
        self.bytes.get(start..self.pos)
    }

    /// Next token parsed as `T`; `what` names the field in the error.
    pub(crate) fn number<T: FromStr>(&mut self, what: &str) -> Result<T, String> {
        let token = self.token().ok_or_else(|| format!("header ends before the {what}"))?;
        std::str::from_utf8(token)
            .ok()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| format!("bad {what} '{}' in header", String::from_utf8_lossy(token)))
    }

    /// Consumes the single whitespace byte that ends the header and returns the raster.
    /// Offset of the next unread byte.
    pub(crate) fn position(&self) -> usize {
        self.pos
    }

    /// Offset of the raster: just past the single whitespace byte that ends the header.
    pub(crate) fn raster_offset(&self) -> Result<usize, String> {
        match self.bytes.get(self.pos) {
            Some(c) if c.is_ascii_whitespace() => Ok(self.pos + 1),
            _ => Err("header is not followed by a single whitespace byte".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_comments_and_raster() {
        let mut r = HeaderReader::new(b"P5\n# made by hand\n3 2 # size\n65535\n\x01\x02");
        assert_eq!(r.token(), Some(&b"P5"[..]));
        assert_eq!(r.number::<u32>("width"), Ok(3));
        assert_eq!(r.number::<u32>("height"), Ok(2));
        assert_eq!(r.number::<u32>("maxval"), Ok(65535));
        assert_eq!(r.raster_offset(), Ok(b"P5\n# made by hand\n3 2 # size\n65535\n".len()));

        let mut r = HeaderReader::new(b"P5 -3");
        r.token();
        assert!(r.number::<u32>("width").is_err());
        assert!(r.number::<u32>("height").is_err());
        let mut r = HeaderReader::new(b"Pf 1 1 -1.0");
        for _ in 0..4 {
            r.token();
        }
        assert!(r.raster_offset().is_err());
    }
}
