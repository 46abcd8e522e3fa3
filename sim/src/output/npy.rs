//! .npy writer: NumPy format version 1.0, little-endian `f32` (`<f4`), C order.
use crate::error::{Result, SimError};
use std::io::Write;

/// The .npy v1.0 header for a `<f4` C-order array of `shape`: magic, version, header length and the
/// dictionary, padded with spaces to a multiple of 64 bytes in total and ending in `'\n'`.
pub fn npy_header_f32(shape: &[usize]) -> Vec<u8> {
    let dims = match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {dims}, }}");
    // 6 magic + 2 version + 2 length + dict + '\n'.
    let unpadded = 10 + dict.len() + 1;
    let total = unpadded.div_ceil(64) * 64;
    dict.extend(std::iter::repeat_n(' ', total - unpadded));
    dict.push('\n');
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out
}

/// Writes `data` (C order, `shape` dimensions) as a NumPy `.npy` v1.0 file of `<f4`.
pub fn write_npy_f32(path: &std::path::Path, shape: &[usize], data: &[f32]) -> Result<()> {
    let n: usize = shape.iter().product();
    if n != data.len() {
        return Err(SimError::invalid(
            "npy shape",
            format!("{shape:?}"),
            format!("holds {n} elements but the data has {}", data.len()),
        ));
    }
    let ctx = || format!("writing {}", path.display());
    let file = std::fs::File::create(path).map_err(|e| SimError::io(ctx(), e))?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    w.write_all(&npy_header_f32(shape))
        .map_err(|e| SimError::io(ctx(), e))?;
    let mut buf = Vec::with_capacity(4 * 16384);
    for chunk in data.chunks(16384) {
        buf.clear();
        for v in chunk {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        w.write_all(&buf).map_err(|e| SimError::io(ctx(), e))?;
    }
    w.flush().map_err(|e| SimError::io(ctx(), e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_bytes_exact() {
        let h = npy_header_f32(&[2, 3]);
        let dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }";
        let mut expected = b"\x93NUMPY\x01\x00".to_vec();
        let pad = 128 - 10 - dict.len() - 1;
        expected.extend_from_slice(&((dict.len() + pad + 1) as u16).to_le_bytes());
        expected.extend_from_slice(dict.as_bytes());
        expected.extend(std::iter::repeat_n(b' ', pad));
        expected.push(b'\n');
        assert_eq!(h.len(), 128);
        assert_eq!(h, expected);
        assert_eq!(&h[8..10], &[118, 0]);
        assert_eq!(npy_header_f32(&[5]).len() % 64, 0);
        assert!(String::from_utf8_lossy(&npy_header_f32(&[5])).contains("'shape': (5,), "));
        assert!(String::from_utf8_lossy(&npy_header_f32(&[])).contains("'shape': (), "));
    }

    #[test]
    fn writes_data_after_header() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.npy");
        write_npy_f32(&p, &[2, 2], &[1.0, 2.0, 3.0, -0.5]).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        assert_eq!(bytes.len(), 128 + 16);
        assert_eq!(&bytes[128..132], &1.0f32.to_le_bytes());
        assert_eq!(&bytes[140..144], &(-0.5f32).to_le_bytes());
        assert!(write_npy_f32(&p, &[3], &[1.0]).is_err());
    }
}
