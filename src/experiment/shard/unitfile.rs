//! One finished unit of a plan on disk: its metrics row and, for reference chunks and runs
//! whose image the figures need, the per-pixel count, mean and M2 in f64 (EXR holds no f64).
//! Written to a temporary name and renamed, so a unit file is whole or absent; the header
//! names the plan and the unit, the trailer repeats the length and holds a checksum of
//! everything before it, so a file cut short, copied from another plan or altered on disk
//! (an edited row, a changed pixel, a film relabelled 4x16 instead of 8x8) is refused
//! before any of it is trusted. Values are checked too ([`Accum::check_values`]).

use crate::experiment::cache::Fnv;
use crate::experiment::chunks::{put_bytes, Accum, Reader};
use crate::experiment::results::Row;
use std::path::Path;

const MAGIC: &[u8; 8] = b"DLUNIT02";
const END: &[u8; 8] = b"DLUNITOK";
/// Length (8 bytes), checksum (8) and end marker (8).
const TRAILER: usize = 24;

/// What a unit produced.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitResult {
    pub row: Option<Row>,
    pub accum: Option<Accum>,
}

/// Who a unit file must belong to.
#[derive(Clone, Copy)]
pub struct Owner<'a> {
    pub plan: &'a str,
    pub index: usize,
    pub name: &'a str,
}

fn header(owner: Owner) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(MAGIC);
    put_bytes(&mut b, owner.plan.as_bytes());
    b.extend_from_slice(&(owner.index as u64).to_le_bytes());
    put_bytes(&mut b, owner.name.as_bytes());
    b
}

/// Writes `r` as unit `owner` at `path`, atomically.
pub fn write(path: &Path, owner: Owner, r: &UnitResult) -> Result<(), String> {
    let mut b = header(owner);
    let row = match &r.row {
        Some(row) => encode_row(row)?,
        None => Vec::new(),
    };
    put_bytes(&mut b, &row);
    match &r.accum {
        Some(a) => {
            b.push(1);
            a.encode(&mut b);
        }
        None => b.push(0),
    }
    let total = (b.len() + TRAILER) as u64;
    b.extend_from_slice(&total.to_le_bytes());
    let sum = checksum(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b.extend_from_slice(END);
    crate::output::write_atomic(path, |tmp| {
        std::fs::write(tmp, &b).map_err(|e| format!("{}: {e}", path.display()))
    })
}

/// The row as results.csv spells it (header and one line): JSON has no NaN, and a 1 spp
/// row's z^2 is NaN.
fn encode_row(row: &Row) -> Result<Vec<u8>, String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.serialize(row).map_err(|e| e.to_string())?;
    w.into_inner().map_err(|e| e.to_string())
}

fn decode_row(b: &[u8]) -> Result<Row, String> {
    let mut r = csv::Reader::from_reader(b);
    let row = r.deserialize::<Row>().next().ok_or("no row")?;
    row.map_err(|e| e.to_string())
}

/// Checks the header against `owner`: a clear reason if it is not this unit's file.
fn check_header(r: &mut Reader, owner: Owner) -> Result<(), String> {
    if r.take(8) != Some(MAGIC.as_slice()) {
        return Err("is not a directlab unit file".into());
    }
    let plan = r.bytes().ok_or("is truncated (in its header)")?;
    if plan != owner.plan.as_bytes() {
        return Err(format!(
            "belongs to plan {}, not to this experiment's plan {}",
            String::from_utf8_lossy(plan),
            owner.plan
        ));
    }
    let index = r.u64().ok_or("is truncated (in its header)")?;
    let name = r.bytes().ok_or("is truncated (in its header)")?;
    if index != owner.index as u64 || name != owner.name.as_bytes() {
        return Err(format!(
            "holds unit {index} ({}), not unit {} ({})",
            String::from_utf8_lossy(name),
            owner.index,
            owner.name
        ));
    }
    Ok(())
}

/// FNV-1a of everything before the checksum.
fn checksum(b: &[u8]) -> u64 {
    Fnv::new().bytes(b).value()
}

/// Checks the trailer of the whole file `b`: as long as its writer said, and every byte before
/// the checksum as it was written.
fn check_trailer(b: &[u8]) -> Result<(), String> {
    if b.len() < TRAILER {
        return Err(format!("is truncated ({} bytes)", b.len()));
    }
    let tail = &b[b.len() - TRAILER..];
    let total = u64::from_le_bytes(tail[..8].try_into().expect("8 bytes"));
    if &tail[16..] != END || total != b.len() as u64 {
        return Err(format!(
            "is truncated or damaged ({} bytes; its end marker is missing or names another length)",
            b.len()
        ));
    }
    let sum = u64::from_le_bytes(tail[8..16].try_into().expect("8 bytes"));
    if sum != checksum(&b[..b.len() - 16]) {
        return Err(
            "is damaged: its contents do not match the checksum it was written with (edited or \
             corrupted on disk); run its shard again"
                .into(),
        );
    }
    Ok(())
}

/// Reads unit `owner` from `path`; errors name the file and what is wrong with it.
pub fn read(path: &Path, owner: Owner) -> Result<UnitResult, String> {
    let bad = |why: String| format!("{}: unit file {why}", path.display());
    let b = std::fs::read(path).map_err(|e| bad(format!("cannot be read: {e}")))?;
    check_header(&mut Reader::new(&b), owner).map_err(bad)?;
    check_trailer(&b).map_err(bad)?;
    let mut r = Reader::new(&b[..b.len() - TRAILER]);
    check_header(&mut r, owner).map_err(bad)?;
    let damaged = || bad("is damaged (its contents do not parse)".into());
    let row = r.bytes().ok_or_else(damaged)?;
    let row = if row.is_empty() {
        None
    } else {
        Some(decode_row(row).map_err(|e| bad(format!("has a bad row: {e}")))?)
    };
    let accum = match r.take(1).ok_or_else(damaged)?[0] {
        0 => None,
        1 => Some(Accum::decode(&mut r).ok_or_else(damaged)?),
        _ => return Err(damaged()),
    };
    if r.left() != 0 {
        return Err(damaged());
    }
    if let Some(a) = &accum {
        a.check_values()
            .map_err(|e| bad(format!("is damaged: {e}")))?;
    }
    Ok(UnitResult { row, accum })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::results::test_row;

    fn scratch() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("directlab-unitfile-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn round_trip_and_every_kind_of_wrong_file_is_named() {
        let dir = scratch();
        let owner = Owner {
            plan: "p1",
            index: 3,
            name: "sweep x 4 spp seed 0",
        };
        let acc = Accum {
            width: 2,
            height: 1,
            n: 4,
            mean: vec![[0.1, 0.2, 0.3], [1.0, f64::MIN_POSITIVE, -0.0]],
            m2: vec![[1e-3; 3], [0.0; 3]],
            seconds: 0.5,
            non_finite_samples: 1,
        };
        let mut row = test_row("light", 4, 0);
        row.mean_z2 = f64::NAN;
        row.top_share = Some(0.25);
        let r = UnitResult {
            row: Some(row),
            accum: Some(acc),
        };
        let path = dir.join("00003.unit");
        write(&path, owner, &r).unwrap();
        let back = read(&path, owner).unwrap();
        let (mut a, mut b) = (back.clone(), r.clone());
        assert!(a.row.as_ref().unwrap().mean_z2.is_nan());
        a.row.as_mut().unwrap().mean_z2 = 0.0;
        b.row.as_mut().unwrap().mean_z2 = 0.0;
        assert_eq!(a, b);
        // Bitwise, including the sign of zero.
        let m = back.accum.unwrap().mean;
        assert_eq!(m[1][2].to_bits(), (-0.0f64).to_bits());

        let other_plan = Owner {
            plan: "p2",
            ..owner
        };
        let e = read(&path, other_plan).unwrap_err();
        assert!(
            e.contains("00003.unit") && e.contains("belongs to plan p1"),
            "{e}"
        );
        let other_unit = Owner { index: 4, ..owner };
        assert!(read(&path, other_unit).unwrap_err().contains("not unit 4"));

        let bytes = std::fs::read(&path).unwrap();
        for cut in [bytes.len() - 1, bytes.len() - 20, 30, 5] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let e = read(&path, owner).unwrap_err();
            assert!(
                e.contains("truncated") || e.contains("not a directlab"),
                "{cut}: {e}"
            );
        }
        // Altered on disk, one byte at a time, anywhere: refused by the checksum (or, in the
        // header, as another unit's file).
        for at in [20, bytes.len() / 2, bytes.len() - 30] {
            let mut b = bytes.clone();
            b[at] ^= 0x10;
            std::fs::write(&path, &b).unwrap();
            let e = read(&path, owner).unwrap_err();
            assert!(
                e.contains("checksum") || e.contains("holds unit"),
                "{at}: {e}"
            );
        }
        // A value no render gives, written with a valid checksum, is still refused.
        let mut nan = r.clone();
        nan.accum.as_mut().unwrap().mean[0][1] = f64::NAN;
        write(&path, owner, &nan).unwrap();
        let e = read(&path, owner).unwrap_err();
        assert!(e.contains("pixel (0, 0)"), "{e}");
        std::fs::write(&path, "x,y\n1,2\n").unwrap();
        assert!(read(&path, owner)
            .unwrap_err()
            .contains("not a directlab unit file"));

        let none = UnitResult {
            row: None,
            accum: None,
        };
        write(&path, owner, &none).unwrap();
        assert_eq!(read(&path, owner).unwrap(), none);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
