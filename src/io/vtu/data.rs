//! Decoding VTK XML data arrays: ASCII numbers, base64 (inline or appended), raw appended bytes,
//! zlib-compressed blocks, UInt32/UInt64 headers, either byte order.
//!
//! Errors are plain messages here; the caller adds where the array is.

use std::io::Read;

use base64::Engine;

/// A VTK scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    pub fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "Int8" => Scalar::I8,
            "UInt8" => Scalar::U8,
            "Int16" => Scalar::I16,
            "UInt16" => Scalar::U16,
            "Int32" => Scalar::I32,
            "UInt32" => Scalar::U32,
            "Int64" => Scalar::I64,
            "UInt64" => Scalar::U64,
            "Float32" => Scalar::F32,
            "Float64" => Scalar::F64,
            _ => return None,
        })
    }

    pub fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    pub fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// How the binary blocks of a file are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// UInt32 or UInt64 headers.
    pub header: Scalar,
    /// Big-endian file.
    pub swap: bool,
    /// zlib-compressed blocks.
    pub compressed: bool,
}

fn array<const N: usize>(bytes: &[u8], swap: bool) -> [u8; N] {
    let mut a = [0; N];
    a.copy_from_slice(&bytes[..N]);
    if swap {
        a.reverse();
    }
    a
}

/// One value of type `ty` at the start of `bytes` (which holds at least `ty.size()` bytes).
fn value(bytes: &[u8], ty: Scalar, swap: bool) -> f64 {
    match ty {
        Scalar::I8 => f64::from(bytes[0] as i8),
        Scalar::U8 => f64::from(bytes[0]),
        Scalar::I16 => f64::from(i16::from_le_bytes(array(bytes, swap))),
        Scalar::U16 => f64::from(u16::from_le_bytes(array(bytes, swap))),
        Scalar::I32 => f64::from(i32::from_le_bytes(array(bytes, swap))),
        Scalar::U32 => f64::from(u32::from_le_bytes(array(bytes, swap))),
        Scalar::F32 => f64::from(f32::from_le_bytes(array(bytes, swap))),
        Scalar::F64 => f64::from_le_bytes(array(bytes, swap)),
        Scalar::I64 => i64::from_le_bytes(array(bytes, swap)) as f64,
        Scalar::U64 => u64::from_le_bytes(array(bytes, swap)) as f64,
    }
}

/// One integer value (64-bit types read exactly; floats are refused by the caller).
fn int_value(bytes: &[u8], ty: Scalar, swap: bool) -> Option<i64> {
    match ty {
        Scalar::I64 => Some(i64::from_le_bytes(array(bytes, swap))),
        Scalar::U64 => i64::try_from(u64::from_le_bytes(array(bytes, swap))).ok(),
        _ => Some(value(bytes, ty, swap) as i64),
    }
}

/// Integers from binary data.
pub fn ints(bytes: &[u8], ty: Scalar, swap: bool) -> Result<Vec<i64>, String> {
    if ty.is_float() {
        return Err("expected an integer array".into());
    }
    bytes
        .chunks_exact(ty.size())
        .map(|c| int_value(c, ty, swap).ok_or_else(|| "integer value out of range".to_string()))
        .collect()
}

/// Floats from binary data.
pub fn floats(bytes: &[u8], ty: Scalar, swap: bool) -> Vec<f64> {
    bytes.chunks_exact(ty.size()).map(|c| value(c, ty, swap)).collect()
}

/// Numbers from ASCII text.
pub fn ascii<T: std::str::FromStr>(text: &[u8]) -> Result<Vec<T>, String> {
    let text = std::str::from_utf8(text).map_err(|_| "non-text bytes in an ASCII array".to_string())?;
    text.split_ascii_whitespace()
        .map(|t| {
            t.parse().map_err(|_| {
                format!("'{}' is not a number of the array's type", t.chars().take(30).collect::<String>())
            })
        })
        .collect()
}

/// Decode base64 text that may be several padded pieces one after the other (VTK and meshio
/// encode the header and the data apart when compressing), ignoring whitespace.
pub fn base64(text: &[u8]) -> Result<Vec<u8>, String> {
    let chars: Vec<u8> = text.iter().copied().filter(|b| !b.is_ascii_whitespace()).collect();
    let mut out = Vec::with_capacity(chars.len() / 4 * 3);
    let mut rest = &chars[..];
    while !rest.is_empty() {
        let end = match rest.iter().position(|&b| b == b'=') {
            Some(p) => p + rest[p..].iter().take_while(|&&b| b == b'=').count(),
            None => rest.len(),
        };
        let piece = &rest[..end];
        base64::engine::general_purpose::STANDARD
            .decode_vec(piece, &mut out)
            .map_err(|e| format!("bad base64 data: {e}"))?;
        rest = &rest[end..];
    }
    Ok(out)
}

/// Read header value `i` (of `layout.header` size) from `bytes`.
fn header_value(bytes: &[u8], i: usize, layout: Layout) -> Result<usize, String> {
    let size = layout.header.size();
    let slice = bytes.get(i * size..(i + 1) * size).ok_or("data block truncated in its header")?;
    let v = int_value(slice, layout.header, layout.swap).ok_or("header value out of range")?;
    usize::try_from(v).map_err(|_| format!("negative size {v} in a data block header"))
}

/// The data of a binary block (header + data, or header + compressed blocks), and the number of
/// bytes the block takes.
pub fn block(bytes: &[u8], layout: Layout) -> Result<(Vec<u8>, usize), String> {
    let hs = layout.header.size();
    if !layout.compressed {
        let n = header_value(bytes, 0, layout)?;
        let data = bytes
            .get(hs..hs.saturating_add(n))
            .ok_or_else(|| format!("data block truncated: {n} bytes announced"))?;
        return Ok((data.to_vec(), hs + n));
    }
    let blocks = header_value(bytes, 0, layout)?;
    let block_size = header_value(bytes, 1, layout)?;
    let last_size = header_value(bytes, 2, layout)?;
    if blocks.saturating_mul(hs) > bytes.len() {
        return Err(format!("{blocks} compressed blocks announced, more than the data holds"));
    }
    let mut at = hs * (3 + blocks);
    let mut out = Vec::new();
    for b in 0..blocks {
        let size = header_value(bytes, 3 + b, layout)?;
        let compressed = bytes.get(at..at.saturating_add(size)).ok_or("compressed data truncated")?;
        let expected = if b + 1 == blocks && last_size > 0 { last_size } else { block_size };
        let mut decoder = flate2::read::ZlibDecoder::new(compressed).take(expected as u64);
        let before = out.len();
        decoder.read_to_end(&mut out).map_err(|e| format!("bad zlib data in block {b}: {e}"))?;
        if out.len() - before != expected {
            return Err(format!("compressed block {b} holds {} bytes, not {expected}", out.len() - before));
        }
        at += size;
    }
    Ok((out, at))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn zlib(data: &[u8]) -> Vec<u8> {
        let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(data).unwrap();
        e.finish().unwrap()
    }

    #[test]
    fn padded_pieces_decode_one_after_the_other() {
        let b64 = |d: &[u8]| base64::engine::general_purpose::STANDARD.encode(d);
        let text = format!("{}\n  {}", b64(b"head"), b64(b"data!"));
        assert_eq!(base64(text.as_bytes()).unwrap(), b"headdata!");
        assert!(base64(b"@@@@").is_err());
    }

    #[test]
    fn compressed_and_plain_blocks() {
        let data: Vec<u8> = (0..100u8).collect();
        let layout = Layout { header: Scalar::U32, swap: false, compressed: true };
        let (a, b) = (zlib(&data[..64]), zlib(&data[64..]));
        let mut bytes = Vec::new();
        for v in [2u32, 64, 36, a.len() as u32, b.len() as u32] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&a);
        bytes.extend_from_slice(&b);
        let (out, used) = block(&bytes, layout).unwrap();
        assert_eq!((out, used), (data.clone(), bytes.len()));
        assert!(block(&bytes[..bytes.len() - 3], layout).is_err());

        let layout = Layout { header: Scalar::U64, swap: false, compressed: false };
        let mut bytes = 100u64.to_le_bytes().to_vec();
        bytes.extend_from_slice(&data);
        assert_eq!(block(&bytes, layout).unwrap().0, data);
        assert!(block(&bytes[..50], layout).is_err());
    }

    #[test]
    fn values_of_every_type() {
        assert_eq!(ints(&(-3i16).to_be_bytes(), Scalar::I16, true).unwrap(), [-3]);
        assert_eq!(
            ints(&u64::MAX.to_le_bytes(), Scalar::U64, false).unwrap_err(),
            "integer value out of range"
        );
        assert_eq!(floats(&1.5f32.to_le_bytes(), Scalar::F32, false), [1.5]);
        assert_eq!(ascii::<i64>(b" 1\n 2 ").unwrap(), [1, 2]);
        assert!(ascii::<i64>(b"1 x").is_err());
    }
}
