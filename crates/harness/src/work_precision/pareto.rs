//! The Pareto front of (error, cost) points: the runs no other run beats on both.

/// Indices of the points on the Pareto front of `points = (error, cost)`, lower being
/// better for both, ordered by increasing cost (and so decreasing error).
///
/// A point is on the front when no other point has an error and a cost both no larger,
/// one of them strictly smaller. Of exact duplicates only the first is kept. Points with a
/// non-finite coordinate are never on the front.
pub fn front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> =
        (0..points.len()).filter(|&i| points[i].0.is_finite() && points[i].1.is_finite()).collect();
    // By cost, then error, then index: the first point of each cost is the best of it.
    order.sort_by(|&a, &b| {
        points[a].1.total_cmp(&points[b].1).then(points[a].0.total_cmp(&points[b].0)).then(a.cmp(&b))
    });
    let mut out = Vec::new();
    let mut best_error = f64::INFINITY;
    for i in order {
        if points[i].0 < best_error {
            best_error = points[i].0;
            out.push(i);
        }
    }
    out
}

/// The Pareto front of each scheme: [`front`] over the points of `schemes[i] == s` alone,
/// for each scheme `s` in order of first appearance, each front cheapest first.
///
/// The study's fronts are per scheme: its error measures (the drop's b error at the end,
/// the channel's steady profile) rank option sets of one scheme, but not schemes whose
/// errors lie elsewhere (on the drop the stabilised MPS keeps b within 0.7 % while its a is
/// 15 % off, docs/notes/mps.md), so a front across schemes would reward a scheme for the one
/// axis it keeps.
pub fn fronts_by_scheme(schemes: &[&str], points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<&str> = Vec::new();
    for &s in schemes {
        if !order.contains(&s) {
            order.push(s);
        }
    }
    let mut out = Vec::new();
    for s in order {
        let mine: Vec<usize> = (0..points.len()).filter(|&i| schemes[i] == s).collect();
        let xy: Vec<(f64, f64)> = mine.iter().map(|&i| points[i]).collect();
        out.extend(front(&xy).into_iter().map(|k| mine[k]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: i is on the front when no j dominates it.
    fn dominated(points: &[(f64, f64)], i: usize) -> bool {
        let (e, c) = points[i];
        points.iter().enumerate().any(|(j, &(ej, cj))| {
            // Both no larger; either one strictly smaller, or an earlier exact duplicate.
            j != i && ej <= e && cj <= c && (ej < e || cj < c || j < i)
        })
    }

    #[test]
    fn simple_front() {
        // (error, cost)
        let p = [(0.01, 1.0), (0.005, 2.0), (0.02, 0.5), (0.012, 1.5), (0.004, 2.0), (0.001, 10.0)];
        assert_eq!(front(&p), vec![2, 0, 4, 5]);
    }

    #[test]
    fn ties_and_bad_points() {
        let p = [(0.01, 1.0), (0.01, 1.0), (f64::NAN, 0.1), (0.02, f64::INFINITY), (0.01, 2.0)];
        assert_eq!(front(&p), vec![0]);
        assert!(front(&[]).is_empty());
        // Same cost, different errors: only the better one.
        assert_eq!(front(&[(0.2, 1.0), (0.1, 1.0)]), vec![1]);
    }

    #[test]
    fn one_front_per_scheme() {
        // (error, cost): the mps point beats every isph point on both, yet each scheme
        // keeps its own front.
        let p = [(0.01, 1.0), (0.001, 0.1), (0.005, 2.0), (0.02, 0.5), (0.002, 0.5), (0.012, 1.5)];
        let s = ["isph", "mps", "isph", "isph", "mps", "wcsph"];
        assert_eq!(fronts_by_scheme(&s, &p), vec![3, 0, 2, 1, 5]);
        assert!(fronts_by_scheme(&[], &[]).is_empty());
    }

    #[test]
    fn agrees_with_brute_force() {
        // A deterministic scatter (linear congruential generator).
        let mut s: u64 = 12345;
        let mut next = || {
            s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            ((s >> 33) % 50) as f64
        };
        for _ in 0..20 {
            let p: Vec<(f64, f64)> = (0..40).map(|_| (next(), next())).collect();
            let mut expect: Vec<usize> = (0..p.len()).filter(|&i| !dominated(&p, i)).collect();
            let mut got = front(&p);
            // Ordered by cost with strictly falling error.
            assert!(got.windows(2).all(|w| p[w[0]].1 <= p[w[1]].1 && p[w[0]].0 > p[w[1]].0));
            got.sort_unstable();
            expect.sort_unstable();
            assert_eq!(got, expect);
        }
    }
}
