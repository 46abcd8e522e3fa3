//! The results table read back for pictures and the summary: numeric columns, and means with 95 %
//! intervals of a metric grouped by the values of one or two axes.
use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// A results table as numbers (`NaN`: an empty or non-numeric cell).
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
    /// The cells as written, for axis values that are not numbers.
    pub text: Vec<Vec<String>>,
}

impl Table {
    pub fn read(path: &Path) -> Result<Table> {
        let mut r =
            csv::Reader::from_path(path).with_context(|| format!("reading {}", path.display()))?;
        let columns: Vec<String> = r.headers()?.iter().map(String::from).collect();
        let mut rows = Vec::new();
        let mut text = Vec::new();
        for rec in r.records() {
            let rec = rec.with_context(|| format!("reading {}", path.display()))?;
            text.push(rec.iter().map(String::from).collect());
            rows.push(
                rec.iter()
                    .map(|c| c.parse::<f64>().unwrap_or(f64::NAN))
                    .collect(),
            );
        }
        Ok(Table {
            columns,
            rows,
            text,
        })
    }

    pub fn col(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }
}

/// Mean, 95 % half-interval (1.96 s / sqrt(n), 0 for one value) and count of the finite values.
pub fn mean_ci(values: &[f64]) -> Option<(f64, f64, usize)> {
    let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    let n = v.len();
    if n == 0 {
        return None;
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    let ci = if n > 1 {
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        1.96 * (var / n as f64).sqrt()
    } else {
        0.0
    };
    Some((mean, ci, n))
}

/// How the values of one axis are grouped: its distinct values when there are few, else bins.
#[derive(Clone, Debug)]
pub struct Groups {
    /// Representative value (a distinct value, or a bin's centre) and label of each group.
    pub centres: Vec<f64>,
    pub labels: Vec<String>,
    /// Group of each row (`None`: no value).
    pub of_row: Vec<Option<usize>>,
    /// Distinct values (a grid axis) rather than bins (sampled axes).
    pub discrete: bool,
}

/// At most this many distinct values are shown one by one; more are binned.
const MAX_DISTINCT: usize = 12;
/// Bins of a sampled axis.
const BINS: usize = 8;

pub fn groups(t: &Table, col: usize, log: bool) -> Groups {
    let values: Vec<f64> = t.rows.iter().map(|r| r[col]).collect();
    let numeric = values.iter().all(|v| v.is_finite());
    if !numeric {
        // Categories in order of first appearance.
        let mut labels: Vec<String> = Vec::new();
        let of_row = t
            .text
            .iter()
            .map(|r| {
                let s = &r[col];
                Some(labels.iter().position(|l| l == s).unwrap_or_else(|| {
                    labels.push(s.clone());
                    labels.len() - 1
                }))
            })
            .collect();
        let centres = (0..labels.len()).map(|k| k as f64).collect();
        return Groups {
            centres,
            labels,
            of_row,
            discrete: true,
        };
    }
    let mut distinct: BTreeMap<u64, f64> = BTreeMap::new();
    for v in &values {
        distinct.insert(ordered(*v), *v);
    }
    if distinct.len() <= MAX_DISTINCT {
        let centres: Vec<f64> = distinct.values().copied().collect();
        let of_row = values
            .iter()
            .map(|v| centres.iter().position(|c| c == v))
            .collect();
        let labels = centres.iter().map(|c| short(*c)).collect();
        return Groups {
            centres,
            labels,
            of_row,
            discrete: true,
        };
    }
    let tr = |x: f64| if log && x > 0.0 { x.ln() } else { x };
    let untr = |x: f64| if log { x.exp() } else { x };
    let lo = values.iter().copied().map(tr).fold(f64::INFINITY, f64::min);
    let hi = values
        .iter()
        .copied()
        .map(tr)
        .fold(f64::NEG_INFINITY, f64::max);
    let width = ((hi - lo) / BINS as f64).max(1e-300);
    let of_row = values
        .iter()
        .map(|v| Some((((tr(*v) - lo) / width) as usize).min(BINS - 1)))
        .collect();
    let centres: Vec<f64> = (0..BINS)
        .map(|k| untr(lo + (k as f64 + 0.5) * width))
        .collect();
    let labels = centres.iter().map(|c| short(*c)).collect();
    Groups {
        centres,
        labels,
        of_row,
        discrete: false,
    }
}

/// A total order key for finite floats.
fn ordered(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 { !b } else { b | (1 << 63) }
}

/// A value with four significant digits.
pub fn short(x: f64) -> String {
    if x == 0.0 || (x.abs() >= 1e-3 && x.abs() < 1e5) {
        let s = format!("{:.4}", x);
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s.is_empty() {
            "0".into()
        } else {
            s.to_string()
        }
    } else {
        format!("{x:.3e}")
    }
}

/// Mean, interval and count of `metric` per group.
pub fn by_group(t: &Table, g: &Groups, metric: usize) -> Vec<Option<(f64, f64, usize)>> {
    let mut per: Vec<Vec<f64>> = vec![Vec::new(); g.centres.len()];
    for (row, k) in t.rows.iter().zip(&g.of_row) {
        if let Some(k) = k {
            per[*k].push(row[metric]);
        }
    }
    per.iter().map(|v| mean_ci(v)).collect()
}

/// Mean of `metric` per pair of groups `(a, b)`, `[a][b]`.
pub fn by_pair(t: &Table, a: &Groups, b: &Groups, metric: usize) -> Vec<Vec<Option<f64>>> {
    let mut per = vec![vec![Vec::new(); b.centres.len()]; a.centres.len()];
    for (k, row) in t.rows.iter().enumerate() {
        if let (Some(i), Some(j)) = (a.of_row[k], b.of_row[k]) {
            per[i][j].push(row[metric]);
        }
    }
    per.iter()
        .map(|r| r.iter().map(|v| mean_ci(v).map(|m| m.0)).collect())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_interval() {
        let (m, ci, n) = mean_ci(&[1.0, 2.0, 3.0, f64::NAN]).unwrap();
        assert_eq!((m, n), (2.0, 3));
        assert!((ci - 1.96 / 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(mean_ci(&[f64::NAN]), None);
        assert_eq!(short(0.125), "0.125");
        assert_eq!(short(2.5), "2.5");
    }
}
