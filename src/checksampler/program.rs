//! What `check-sampler` needs of the user's program, whatever the transport: a request (a
//! JSON header and rows of f64) answered by rows of f64. Both transports ([`super::pipe`],
//! [`super::files`]) check a reply the same way here.

use serde_json::Value;

/// The user's sampler program, reached through some transport.
pub trait Program {
    /// Sends `header` with `payload` (`rows` rows) and returns the reply's values and its
    /// column count, one of `cols`; `what` names the phase and batch in errors.
    fn call(
        &mut self,
        header: Value,
        payload: &[f64],
        rows: usize,
        cols: &[usize],
        what: &str,
    ) -> Result<(Vec<f64>, usize), String>;

    /// Tells the program the check is over.
    fn finish(&mut self);
}

/// Checks a reply's header and values: `rows` rows of one of the `cols` column counts, all
/// finite. Returns the column count.
pub fn validate(
    head: &Value,
    values: &[f64],
    rows: usize,
    cols: &[usize],
) -> Result<usize, String> {
    let count = head["count"].as_u64();
    let got = head["cols"].as_u64().map(|c| c as usize);
    let expected = || {
        let c: Vec<String> = cols.iter().map(|c| c.to_string()).collect();
        format!("{rows} rows x {} columns", c.join(" or "))
    };
    let c = match got {
        Some(c) if count == Some(rows as u64) && cols.contains(&c) => c,
        _ => {
            return Err(format!(
                "expected a reply of {}, got header {head}",
                expected()
            ))
        }
    };
    if values.len() != rows * c {
        return Err(format!(
            "expected {} values ({}), got {}",
            rows * c,
            expected(),
            values.len()
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "non-finite value {} in row {}, column {}",
            values[i],
            i / c,
            i % c
        ));
    }
    Ok(c)
}
