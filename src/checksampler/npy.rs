//! NumPy `.npy` files of little-endian f64, two-dimensional (rows x cols, C order): what the
//! files transport of `check-sampler` exchanges. Version 1.0 is written; 1.0, 2.0 and 3.0
//! are read. A one-dimensional array reads as one column.

use std::path::Path;

const MAGIC: &[u8] = b"\x93NUMPY";

/// The file's bytes for `rows` x `cols` values (`values.len() == rows * cols`).
pub fn encode(values: &[f64], rows: usize, cols: usize) -> Vec<u8> {
    assert_eq!(
        values.len(),
        rows * cols,
        "npy: values do not fill the shape"
    );
    let mut header =
        format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    // Magic (6) + version (2) + length (2) + header + newline, padded to 64 bytes.
    let unpadded = MAGIC.len() + 4 + header.len() + 1;
    header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + values.len() * 8);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Writes an array through a temporary file, so a reader never sees half of it.
pub fn write(path: &Path, values: &[f64], rows: usize, cols: usize) -> Result<(), String> {
    let tmp = path.with_extension("npy.part");
    std::fs::write(&tmp, encode(values, rows, cols))
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Reads an array: (values, rows, cols).
pub fn read(path: &Path) -> Result<(Vec<f64>, usize, usize), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    decode(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Parses a file's bytes: (values, rows, cols).
pub fn decode(bytes: &[u8]) -> Result<(Vec<f64>, usize, usize), String> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err("not a .npy file (no \\x93NUMPY magic)".into());
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes")) as usize,
            12,
        ),
        v => return Err(format!("unknown .npy version {v}")),
    };
    let header = bytes
        .get(start..start + len)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or("the .npy header is cut short or not text")?;
    let field = |key: &str| -> Result<&str, String> {
        let at = header
            .find(&format!("'{key}'"))
            .ok_or_else(|| format!("the .npy header {header:?} has no '{key}'"))?;
        let rest = header[at + key.len() + 2..].trim_start();
        Ok(rest.strip_prefix(':').unwrap_or(rest).trim_start())
    };
    let descr = field("descr")?;
    if !(descr.starts_with("'<f8'") || descr.starts_with("'float64'")) {
        return Err(format!(
            "expected little-endian float64 ('<f8'), got descr {}",
            descr.split(',').next().unwrap_or(descr)
        ));
    }
    if field("fortran_order")?.starts_with("True") {
        return Err("expected a C-order array (fortran_order False)".into());
    }
    let shape = field("shape")?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| format!("cannot read the shape in {header:?}"))?;
    let dims: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<usize>()
                .map_err(|e| format!("shape ({inner}): {e}"))
        })
        .collect::<Result<_, _>>()?;
    let (rows, cols) = match dims[..] {
        [n] => (n, 1),
        [n, c] => (n, c),
        _ => {
            return Err(format!(
                "expected a 1- or 2-dimensional array, got shape ({inner})"
            ))
        }
    };
    let data = &bytes[start + len..];
    if data.len() != rows * cols * 8 {
        return Err(format!(
            "shape ({inner}) needs {} bytes of data, the file has {}",
            rows * cols * 8,
            data.len()
        ));
    }
    let values = data
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
    Ok((values, rows, cols))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_header_alignment() {
        let v: Vec<f64> = (0..12).map(|i| i as f64 * 0.5 - 1.0).collect();
        let b = encode(&v, 4, 3);
        let len = u16::from_le_bytes([b[8], b[9]]) as usize;
        assert_eq!((10 + len) % 64, 0, "data starts on a 64-byte boundary");
        assert_eq!(decode(&b).unwrap(), (v, 4, 3));
    }

    /// Bytes exactly as numpy 2.x writes `np.save(f, np.arange(3.0))`.
    #[test]
    fn reads_what_numpy_writes() {
        let mut b = b"\x93NUMPY\x01\x00v\x00".to_vec();
        let h = "{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }";
        b.extend_from_slice(h.as_bytes());
        b.extend(std::iter::repeat_n(b' ', 118 - h.len() - 1));
        b.push(b'\n');
        for x in [0.0f64, 1.0, 2.0] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        assert_eq!(decode(&b).unwrap(), (vec![0.0, 1.0, 2.0], 3, 1));
    }

    #[test]
    fn wrong_files_are_named() {
        assert!(decode(b"PK\x03\x04").unwrap_err().contains("magic"));
        let mut b = encode(&[1.0], 1, 1);
        let at = b.windows(3).position(|w| w == b"<f8").unwrap();
        b[at..at + 3].copy_from_slice(b"<f4");
        assert!(decode(&b).unwrap_err().contains("'<f8'"));
        let b = encode(&[1.0, 2.0], 2, 1);
        assert!(decode(&b[..b.len() - 8])
            .unwrap_err()
            .contains("needs 16 bytes"));
    }
}
