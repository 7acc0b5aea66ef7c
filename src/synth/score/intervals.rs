//! Interval arithmetic on arc lengths along a segment, for the scorer:
//! clipping a linear function's range, unions and intersections.

/// `{s ∈ [s0, s1] : lo ≤ a + b s ≤ hi}`.
pub fn clip_linear(a: f64, b: f64, lo: f64, hi: f64, s0: f64, s1: f64) -> Option<(f64, f64)> {
    if b.abs() < 1e-12 {
        return (a >= lo && a <= hi).then_some((s0, s1));
    }
    let (x, y) = ((lo - a) / b, (hi - a) / b);
    let (x, y) = (x.min(y), x.max(y));
    let (r0, r1) = (s0.max(x), s1.min(y));
    (r0 <= r1).then_some((r0, r1))
}

/// Total length of a union of intervals (sorts them in place).
pub fn union_length(iv: &mut [(f64, f64)]) -> f64 {
    iv.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    let mut cur: Option<(f64, f64)> = None;
    for &(a, b) in iv.iter() {
        match cur {
            Some((c0, c1)) if a <= c1 => cur = Some((c0, c1.max(b))),
            Some((c0, c1)) => {
                total += c1 - c0;
                cur = Some((a, b));
            }
            None => cur = Some((a, b)),
        }
    }
    if let Some((c0, c1)) = cur {
        total += c1 - c0;
    }
    total
}

/// The union as sorted, disjoint intervals.
pub fn normalize(mut iv: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    iv.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(iv.len());
    for (a, b) in iv {
        match out.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
    out
}

/// Length of the intersection of two sorted, disjoint interval lists.
pub fn intersection_length(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    let (mut i, mut j, mut total) = (0, 0, 0.0);
    while i < a.len() && j < b.len() {
        let lo = a[i].0.max(b[j].0);
        let hi = a[i].1.min(b[j].1);
        if hi > lo {
            total += hi - lo;
        }
        if a[i].1 < b[j].1 {
            i += 1;
        } else {
            j += 1;
        }
    }
    total
}
