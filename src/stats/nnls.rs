//! Non-negative least squares (Lawson and Hanson 1974, the active-set method): the x >= 0
//! that minimises |A x - b|. The cost model fits seconds to counts with it, because a
//! negative cost per ray is not a cost: plain least squares on collinear counts (a strategy
//! that always casts one shadow ray per light sample) trades a large positive coefficient
//! for a large negative one and then predicts nonsense for the next strategy.

/// The non-negative least-squares solution of `a` x = `b`, `a` given by rows (all of one
/// length, the number of unknowns). Columns are scaled to unit length inside, so unknowns of
/// very different sizes (a constant per run beside counts of 1e8 rays) are solved alike.
/// An all-zero column gets 0.
pub fn nnls(a: &[Vec<f64>], b: &[f64]) -> Vec<f64> {
    let n = a.first().map_or(0, Vec::len);
    assert!(a.iter().all(|r| r.len() == n) && a.len() == b.len());
    let norm_of: Vec<f64> = (0..n)
        .map(|j| a.iter().map(|r| r[j] * r[j]).sum::<f64>().sqrt())
        .collect();
    let norm = &norm_of;
    let col = |j: usize| a.iter().map(move |r| r[j] / norm[j]);
    let usable: Vec<bool> = norm.iter().map(|&s| s > 0.0 && s.is_finite()).collect();
    let mut x = vec![0.0; n];
    let mut passive = vec![false; n];
    let residual = |x: &[f64]| -> Vec<f64> {
        b.iter()
            .zip(a)
            .map(|(bi, r)| {
                bi - (0..n)
                    .filter(|&j| usable[j])
                    .map(|j| r[j] / norm[j] * x[j])
                    .sum::<f64>()
            })
            .collect()
    };
    let scale = b
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let tol = 1e-12 * scale;
    for _ in 0..3 * n + 3 {
        let r = residual(&x);
        // The gradient of -|r|^2 / 2 over the columns still held at zero.
        let best = (0..n)
            .filter(|&j| usable[j] && !passive[j])
            .map(|j| (j, col(j).zip(&r).map(|(c, ri)| c * ri).sum::<f64>()))
            .max_by(|p, q| p.1.total_cmp(&q.1));
        let Some((j, w)) = best else { break };
        if !(w > tol) {
            break;
        }
        passive[j] = true;
        loop {
            let s = solve_passive(a, b, norm, &passive);
            if (0..n).all(|i| !passive[i] || s[i] > 0.0) {
                x = s;
                break;
            }
            // Step from x towards s until the first passive unknown reaches zero.
            let alpha = (0..n)
                .filter(|&i| passive[i] && s[i] <= 0.0)
                .map(|i| x[i] / (x[i] - s[i]))
                .fold(f64::INFINITY, f64::min);
            for i in 0..n {
                x[i] += alpha * (s[i] - x[i]);
                if passive[i] && x[i] <= 1e-15 {
                    passive[i] = false;
                    x[i] = 0.0;
                }
            }
            if !passive.iter().any(|&p| p) {
                break;
            }
        }
    }
    x.iter()
        .zip(norm)
        .map(|(xi, s)| if *s > 0.0 { xi / s } else { 0.0 })
        .collect()
}

/// Unconstrained least squares on the passive columns (scaled), the others held at zero:
/// the normal equations, solved by Gaussian elimination with partial pivoting (a handful of
/// unknowns); a column that adds nothing (collinear with the others) gets 0.
fn solve_passive(a: &[Vec<f64>], b: &[f64], norm: &[f64], passive: &[bool]) -> Vec<f64> {
    let idx: Vec<usize> = (0..passive.len()).filter(|&j| passive[j]).collect();
    let k = idx.len();
    let mut m = vec![vec![0.0; k + 1]; k];
    for (r, bi) in a.iter().zip(b) {
        for (p, &i) in idx.iter().enumerate() {
            let ci = r[i] / norm[i];
            for (q, &j) in idx.iter().enumerate() {
                m[p][q] += ci * r[j] / norm[j];
            }
            m[p][k] += ci * bi;
        }
    }
    let mut pivot_of = vec![None; k];
    let mut row = 0;
    for c in 0..k {
        let Some(p) = (row..k).max_by(|&p, &q| m[p][c].abs().total_cmp(&m[q][c].abs())) else {
            break;
        };
        if !(m[p][c].abs() > 1e-12) {
            continue;
        }
        m.swap(row, p);
        let pivot = m[row].clone();
        for (r2, other) in m.iter_mut().enumerate() {
            if r2 != row {
                let f = other[c] / pivot[c];
                for (o, p) in other[c..].iter_mut().zip(&pivot[c..]) {
                    *o -= f * p;
                }
            }
        }
        pivot_of[c] = Some(row);
        row += 1;
    }
    let mut s = vec![0.0; passive.len()];
    for (c, &i) in idx.iter().enumerate() {
        if let Some(r) = pivot_of[c] {
            s[i] = m[r][k] / m[r][c];
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= tol * y.abs().max(1.0))
    }

    #[test]
    fn recovers_non_negative_coefficients_of_very_different_sizes() {
        // Seconds = 0.01 per run + 3e-9 per ray + 0 per evaluation, exactly.
        let truth = [0.01, 3e-9, 0.0];
        let a: Vec<Vec<f64>> = (1..8)
            .map(|k| vec![1.0, 1e6 * k as f64, 5e5 * ((k * k) % 5) as f64])
            .collect();
        let b: Vec<f64> = a
            .iter()
            .map(|r| r.iter().zip(&truth).map(|(x, t)| x * t).sum())
            .collect();
        let x = nnls(&a, &b);
        assert!(close(&x[..2], &truth[..2], 1e-9), "{x:?}");
        assert!(x[2].abs() < 1e-15, "{x:?}");
    }

    #[test]
    fn a_coefficient_least_squares_makes_negative_is_held_at_zero() {
        // Hand-worked: b = (1, 2, 1) on columns (1,1,1) and (0,1,2). Least squares gives
        // (4/3, 0) + ... = slope 0, intercept 4/3; with b = (2, 1, 0) least squares has
        // slope -1, so NNLS drops the slope and keeps the mean, 1.
        let a = vec![vec![1.0, 0.0], vec![1.0, 1.0], vec![1.0, 2.0]];
        let x = nnls(&a, &[1.0, 2.0, 1.0]);
        assert!(close(&x, &[4.0 / 3.0, 0.0], 1e-12), "{x:?}");
        let x = nnls(&a, &[2.0, 1.0, 0.0]);
        assert!(close(&x, &[1.0, 0.0], 1e-12), "{x:?}");
        // A column of zeros and a collinear copy do not break it.
        let a = vec![vec![1.0, 0.0, 2.0], vec![2.0, 0.0, 4.0]];
        let x = nnls(&a, &[3.0, 6.0]);
        let fit: Vec<f64> = a.iter().map(|r| r[0] * x[0] + r[2] * x[2]).collect();
        assert!(
            close(&fit, &[3.0, 6.0], 1e-12) && x.iter().all(|v| *v >= 0.0),
            "{x:?}"
        );
    }
}
