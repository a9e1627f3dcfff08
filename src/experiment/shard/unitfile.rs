//! One finished unit of a plan on disk: its metrics row and, for reference chunks and runs
//! whose image the figures need, the per-pixel count, mean and M2 in f64 (EXR holds no f64).
//! Written to a temporary name and renamed, so a unit file is whole or absent; the header
//! names the plan and the unit, the trailer repeats the length, so a file cut short or
//! copied from another plan is recognised without trusting its contents.

use crate::experiment::chunks::{put_bytes, Accum, Reader};
use crate::experiment::results::Row;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

const MAGIC: &[u8; 8] = b"DLUNIT01";
const END: &[u8; 8] = b"DLUNITOK";

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
    let total = b.len() as u64 + 16;
    b.extend_from_slice(&total.to_le_bytes());
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

/// Checks the trailer: the file is as long as its writer said.
fn check_trailer(tail: &[u8], len: u64) -> Result<(), String> {
    let total = u64::from_le_bytes(tail[..8].try_into().expect("16 bytes"));
    if &tail[8..] != END || total != len {
        return Err(format!(
            "is truncated or damaged ({len} bytes; its end marker is missing or names another length)"
        ));
    }
    Ok(())
}

/// Whether `path` holds unit `owner` complete, reading only its header and trailer: Ok(false)
/// if absent, Err(reason) if something else is there.
pub fn is_done(path: &Path, owner: Owner) -> Result<bool, String> {
    let mut f = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(format!("cannot be read: {e}")),
    };
    let len = f
        .metadata()
        .map_err(|e| format!("cannot be read: {e}"))?
        .len();
    let want = header(owner).len() as u64;
    if len < want + 16 {
        check_header(&mut Reader::new(&read_some(&mut f, len)?), owner)?;
        return Err(format!("is truncated ({len} bytes)"));
    }
    check_header(&mut Reader::new(&read_some(&mut f, want)?), owner)?;
    let mut tail = [0u8; 16];
    f.seek(SeekFrom::End(-16))
        .and_then(|_| f.read_exact(&mut tail))
        .map_err(|e| format!("cannot be read: {e}"))?;
    check_trailer(&tail, len)?;
    Ok(true)
}

fn read_some(f: &mut std::fs::File, n: u64) -> Result<Vec<u8>, String> {
    let mut b = Vec::new();
    f.take(n)
        .read_to_end(&mut b)
        .map_err(|e| format!("cannot be read: {e}"))?;
    Ok(b)
}

/// Reads unit `owner` from `path`; errors name the file and what is wrong with it.
pub fn read(path: &Path, owner: Owner) -> Result<UnitResult, String> {
    let bad = |why: String| format!("{}: unit file {why}", path.display());
    let b = std::fs::read(path).map_err(|e| bad(format!("cannot be read: {e}")))?;
    let mut r = Reader::new(&b);
    check_header(&mut r, owner).map_err(bad)?;
    if b.len() < 16 {
        return Err(bad("is truncated".into()));
    }
    check_trailer(&b[b.len() - 16..], b.len() as u64).map_err(bad)?;
    let mut r = Reader::new(&b[..b.len() - 16]);
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
        assert_eq!(is_done(&path, owner), Ok(false));
        write(&path, owner, &r).unwrap();
        assert_eq!(is_done(&path, owner), Ok(true));
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
        assert!(is_done(&path, other_plan).unwrap_err().contains("plan p1"));
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
            assert!(is_done(&path, owner).is_err(), "{cut}");
        }
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
