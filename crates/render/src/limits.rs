//! Bounds on the counts a user gives (samples per pixel, seeds, shards, test counts, grid
//! sizes), checked before anything is allocated or rendered. Every count goes through
//! [`count`], so a typo such as 4294967295 is a clear error naming where it came from, the
//! limit and why it exists, never an abort, a 32 GB allocation or hours of work without a
//! word.

/// A bound on one kind of count: its largest accepted value and why.
#[derive(Clone, Copy, Debug)]
pub struct Bound {
    /// The largest accepted value.
    pub max: u64,
    /// Why larger values are refused, as the error states it.
    pub why: &'static str,
}

/// Samples per pixel of one render or run.
pub const SPP: Bound = Bound {
    max: 1 << 24,
    why: "16.8 million samples per pixel is days of work at any resolution; split a larger \
          reference into shards",
};

/// Light or BSDF samples per camera sample.
pub const TECHNIQUE_SAMPLES: Bound = Bound {
    max: 1024,
    why: "beyond this a camera sample's cost no longer shows the estimator",
};

/// Seeds of a sweep or measurement.
pub const SEEDS: Bound = Bound {
    max: 100_000,
    why: "statistics over seeds settle long before this",
};

/// Shards of a plan (a Slurm job array's size is far smaller by default).
pub const SHARDS: Bound = Bound {
    max: 100_000,
    why: "a plan's units go to at most this many shards; more only leaves shards empty",
};

/// Samples of one chi-square or t-test case.
pub const TEST_SAMPLES: Bound = Bound {
    max: 1 << 30,
    why: "a test of 10^9 samples already resolves errors far below any histogram's noise",
};

/// Incident directions (or cases) of one test file.
pub const TEST_COUNT: Bound = Bound {
    max: 10_000,
    why: "each direction is a chi-square test of its own; this many already take hours",
};

/// Checks `value` of `what` (e.g. "--spp", "integrator.emitter_samples in scene.xml")
/// against `bound`: the value back, or an error naming `what`, the value and the limit.
pub fn count(value: u64, what: &str, bound: Bound) -> Result<u64, String> {
    if value > bound.max {
        return Err(format!(
            "{what} is {value}; at most {} is accepted ({})",
            bound.max, bound.why
        ));
    }
    Ok(value)
}

/// [`count`] of a count given as a float (a file that spells it 1e9): refused unless it is a
/// whole number within the bound.
pub fn count_f64(value: f64, what: &str, bound: Bound) -> Result<u64, String> {
    if !(value >= 0.0 && value.fract() == 0.0) {
        return Err(format!(
            "{what} is {value}; expected a whole number of at least 0"
        ));
    }
    if value > bound.max as f64 {
        return Err(format!(
            "{what} is {value}; at most {} is accepted ({})",
            bound.max, bound.why
        ));
    }
    Ok(value as u64)
}

/// A command-line parser of a count within `bound` and at least `min`, for clap's
/// `value_parser` (e.g. `--spp`, `--samples`); the error names `what`.
pub fn parser(
    what: &'static str,
    min: u64,
    bound: Bound,
) -> impl Fn(&str) -> Result<u64, String> + Clone + Send + Sync + 'static {
    move |s: &str| {
        let n: u64 = s
            .trim()
            .parse()
            .map_err(|_| format!("'{s}' is not a whole number"))?;
        if n < min {
            return Err(format!("{what} is {n}; at least {min} is needed"));
        }
        count(n, what, bound)
    }
}

/// Samples per pixel on the command line (`--spp`): a whole number from 1 to [`SPP`]'s bound.
pub fn parse_spp(s: &str) -> Result<u32, String> {
    parser("--spp", 1, SPP)(s).map(|n| n as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_beyond_its_bound_is_refused_with_where_it_came_from() {
        assert_eq!(count(16, "--spp", SPP), Ok(16));
        assert_eq!(count(SPP.max, "--spp", SPP), Ok(SPP.max));
        let e = count(4294967295, "--spp", SPP).unwrap_err();
        assert!(
            e.starts_with("--spp is 4294967295; at most 16777216"),
            "{e}"
        );
        assert!(e.contains("shards"), "{e}");
        assert_eq!(count_f64(1e3, "testCount", TEST_SAMPLES), Ok(1000));
        let e = count_f64(1e12, "testCount in t.xml", TEST_SAMPLES).unwrap_err();
        assert!(
            e.contains("testCount in t.xml is 1000000000000; at most 1073741824"),
            "{e}"
        );
        for bad in [-1.0, 2.5, f64::NAN, f64::INFINITY] {
            assert!(count_f64(bad, "n", SEEDS).is_err(), "{bad}");
        }
    }
}
