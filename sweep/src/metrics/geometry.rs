//! Geometry over robot positions: nearest-neighbour distances, clusters, contacts.
use glam::Vec2;

/// `(1/N) sum_i min_{j != i} |p_i - p_j|`; `None` for fewer than two robots.
pub fn mean_nearest_neighbour(p: &[Vec2]) -> Option<f64> {
    if p.len() < 2 {
        return None;
    }
    let total: f64 = p
        .iter()
        .enumerate()
        .map(|(i, a)| {
            p.iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, b)| a.distance_squared(*b) as f64)
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .sum();
    Some(total / p.len() as f64)
}

/// Connected groups of robots linked when their centres are at most `link` apart (single linkage).
pub fn clusters(p: &[Vec2], link: f32) -> usize {
    let mut parent: Vec<usize> = (0..p.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let l2 = link * link;
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            if p[i].distance_squared(p[j]) <= l2 {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    (0..p.len()).filter(|&i| root(&mut parent, i) == i).count()
}

/// Pairs `(i, j)`, `i < j`, closer than `reach`, sorted; a bucket grid keeps large swarms linear.
pub fn contacts(p: &[Vec2], reach: f32, out: &mut Vec<(u32, u32)>) {
    out.clear();
    let r2 = reach * reach;
    if p.len() <= 64 {
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                if p[i].distance_squared(p[j]) < r2 {
                    out.push((i as u32, j as u32));
                }
            }
        }
        return;
    }
    let (lo, hi) = p
        .iter()
        .fold((p[0], p[0]), |(lo, hi), q| (lo.min(*q), hi.max(*q)));
    let cell = reach.max(1e-6);
    let nx = (((hi.x - lo.x) / cell) as usize + 1).min(4096);
    let ny = (((hi.y - lo.y) / cell) as usize + 1).min(4096);
    let key = |q: Vec2| {
        let cx = (((q.x - lo.x) / cell) as usize).min(nx - 1);
        let cy = (((q.y - lo.y) / cell) as usize).min(ny - 1);
        (cx, cy)
    };
    let mut order: Vec<(usize, u32)> = p
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let (cx, cy) = key(*q);
            (cy * nx + cx, i as u32)
        })
        .collect();
    order.sort_unstable();
    let mut start = vec![0usize; nx * ny + 1];
    for &(c, _) in &order {
        start[c + 1] += 1;
    }
    for c in 0..nx * ny {
        start[c + 1] += start[c];
    }
    for (i, q) in p.iter().enumerate() {
        let (cx, cy) = key(*q);
        for y in cy.saturating_sub(1)..=(cy + 1).min(ny - 1) {
            for x in cx.saturating_sub(1)..=(cx + 1).min(nx - 1) {
                let c = y * nx + x;
                for &(_, j) in &order[start[c]..start[c + 1]] {
                    if (j as usize) > i && q.distance_squared(p[j as usize]) < r2 {
                        out.push((i as u32, j));
                    }
                }
            }
        }
    }
    out.sort_unstable();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_neighbours_and_clusters() {
        let p = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.1, 0.0),
            Vec2::new(1.0, 0.0),
        ];
        let nn = mean_nearest_neighbour(&p).unwrap();
        assert!((nn - (0.1 + 0.1 + 0.9) / 3.0).abs() < 1e-6, "{nn}");
        assert_eq!(clusters(&p, 0.15), 2);
        assert_eq!(clusters(&p, 1.0), 1);
        assert_eq!(clusters(&p, 0.05), 3);
        assert_eq!(mean_nearest_neighbour(&p[..1]), None);
    }

    #[test]
    fn bucketed_contacts_match_all_pairs() {
        let p: Vec<Vec2> = (0..300)
            .map(|k| {
                let a = k as f32 * 0.618;
                Vec2::new((a * 7.3).fract() * 2.0, (a * 3.1).fract() * 1.0)
            })
            .collect();
        let mut fast = Vec::new();
        contacts(&p, 0.05, &mut fast);
        let mut slow = Vec::new();
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                if p[i].distance(p[j]) < 0.05 {
                    slow.push((i as u32, j as u32));
                }
            }
        }
        assert!(!slow.is_empty());
        assert_eq!(fast, slow);
    }
}
