//! The `.npy` header dict: the subset of Python literals NumPy writes (`descr`, `fortran_order`,
//! `shape`, each once) parsed strictly, and the element types it may name.

/// Element types accepted by [`load_npy`](super::npy::load_npy) (either byte order where it applies).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NpyDtype {
    /// `|u1`
    U8,
    /// `<u2` / `>u2`
    U16,
    /// `<f4` / `>f4`
    F32,
    /// `<f8` / `>f8`
    F64,
}

/// Converts one stored element (exactly `item_size` bytes) to f64.
pub(super) type DecodeFn = fn(&[u8]) -> f64;

pub(super) struct Header {
    pub(super) descr: String,
    pub(super) dtype: NpyDtype,
    pub(super) item_size: usize,
    pub(super) decode: DecodeFn,
    pub(super) fortran_order: bool,
    pub(super) shape: Vec<usize>,
}

/// The header dict's `descr`, `fortran_order` and `shape`, each present once.
pub(super) fn parse_dict(text: &str) -> std::result::Result<(String, bool, Vec<usize>), String> {
    let mut p = Parser {
        s: text.as_bytes(),
        i: 0,
    };
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    p.expect(b'{')?;
    loop {
        p.skip_ws();
        if p.eat(b'}') {
            break;
        }
        let key = p.string()?;
        p.expect(b':')?;
        let dup = match key.as_str() {
            "descr" => descr.replace(p.string()?).is_some(),
            "fortran_order" => fortran.replace(p.boolean()?).is_some(),
            "shape" => shape.replace(p.tuple()?).is_some(),
            other => return Err(format!("unexpected header key '{other}'")),
        };
        if dup {
            return Err(format!("duplicate header key '{key}'"));
        }
        p.skip_ws();
        if !p.eat(b',') {
            p.expect(b'}')?;
            break;
        }
    }
    p.skip_ws();
    if p.i != p.s.len() {
        return Err("unexpected text after the header dict".into());
    }
    Ok((
        descr.ok_or("header lacks 'descr'")?,
        fortran.ok_or("header lacks 'fortran_order'")?,
        shape.ok_or("header lacks 'shape'")?,
    ))
}

/// The element type, size and decoder of a supported `descr`.
pub(super) fn dtype_of(descr: &str) -> Option<(NpyDtype, usize, DecodeFn)> {
    let known: (NpyDtype, usize, DecodeFn) = match descr {
        "|u1" => (NpyDtype::U8, 1, |b| f64::from(b[0])),
        "<u2" => (NpyDtype::U16, 2, |b| f64::from(u16::from_le_bytes([b[0], b[1]]))),
        ">u2" => (NpyDtype::U16, 2, |b| f64::from(u16::from_be_bytes([b[0], b[1]]))),
        "<f4" => (NpyDtype::F32, 4, |b| {
            f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        }),
        ">f4" => (NpyDtype::F32, 4, |b| {
            f64::from(f32::from_be_bytes([b[0], b[1], b[2], b[3]]))
        }),
        "<f8" => (NpyDtype::F64, 8, |b| f64::from_le_bytes(array8(b))),
        ">f8" => (NpyDtype::F64, 8, |b| f64::from_be_bytes(array8(b))),
        _ => return None,
    };
    Some(known)
}

pub(super) fn parse_header(text: &str) -> std::result::Result<Header, String> {
    let (descr, fortran_order, shape) = parse_dict(text)?;
    let (dtype, item_size, decode) = dtype_of(&descr)
        .ok_or_else(|| format!("unsupported dtype '{descr}' (supported: |u1 <u2 >u2 <f4 >f4 <f8 >f8)"))?;
    Ok(Header {
        descr,
        dtype,
        item_size,
        decode,
        fortran_order,
        shape,
    })
}

// The decode fns above index within `chunks_exact(item_size)` chunks, so they cannot panic.
fn array8(b: &[u8]) -> [u8; 8] {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[..8]);
    a
}

/// Minimal parser for the Python literal subset NumPy writes in headers.
struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self.s.get(self.i).is_some_and(|c| c.is_ascii_whitespace()) {
            self.i += 1;
        }
    }

    fn eat(&mut self, c: u8) -> bool {
        self.skip_ws();
        let hit = self.s.get(self.i) == Some(&c);
        if hit {
            self.i += 1;
        }
        hit
    }

    fn expect(&mut self, c: u8) -> std::result::Result<(), String> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(format!("expected '{}' at header offset {}", char::from(c), self.i))
        }
    }

    fn string(&mut self) -> std::result::Result<String, String> {
        self.skip_ws();
        let quote = match self.s.get(self.i) {
            Some(&q @ (b'\'' | b'"')) => q,
            _ => return Err(format!("expected a string at header offset {}", self.i)),
        };
        let start = self.i + 1;
        let len = self.s[start..]
            .iter()
            .position(|&c| c == quote || c == b'\\')
            .ok_or("unterminated string in header")?;
        if self.s[start + len] == b'\\' {
            return Err("escapes in header strings are not supported".into());
        }
        self.i = start + len + 1;
        Ok(String::from_utf8_lossy(&self.s[start..start + len]).into_owned())
    }

    fn boolean(&mut self) -> std::result::Result<bool, String> {
        self.skip_ws();
        for (word, value) in [(&b"True"[..], true), (&b"False"[..], false)] {
            if self.s[self.i..].starts_with(word) {
                self.i += word.len();
                return Ok(value);
            }
        }
        Err(format!("expected True or False at header offset {}", self.i))
    }

    /// `()`, `(n,)`, `(a, b)`, `(a, b,)`; Python 2's `3L` suffix is accepted.
    fn tuple(&mut self) -> std::result::Result<Vec<usize>, String> {
        self.expect(b'(')?;
        let mut dims = Vec::new();
        let mut trailing_comma = false;
        while !self.eat(b')') {
            dims.push(self.uint()?);
            trailing_comma = self.eat(b',');
            if !trailing_comma {
                self.expect(b')')?;
                break;
            }
        }
        if dims.len() == 1 && !trailing_comma {
            // "(5)" is an int in Python, not a tuple; NumPy writes "(5,)".
            return Err("1-D shape must be written '(n,)'".into());
        }
        Ok(dims)
    }

    fn uint(&mut self) -> std::result::Result<usize, String> {
        self.skip_ws();
        let start = self.i;
        while self.s.get(self.i).is_some_and(u8::is_ascii_digit) {
            self.i += 1;
        }
        let dim = std::str::from_utf8(&self.s[start..self.i])
            .ok()
            .and_then(|d| d.parse::<usize>().ok())
            .ok_or_else(|| format!("bad shape dimension at header offset {start}"))?;
        if self.s.get(self.i) == Some(&b'L') {
            self.i += 1;
        }
        Ok(dim)
    }
}
