//! The paper's claims as the issue states them, for two seeds and both trail layouts, with the paper's
//! 20 trials per group:
//! G3 >= 95 % at food; G1 over >= 5 end points with none above half; G1 < G2 < G3 at food;
//! S(t) falls by half during aggregation and rises by half after an alarm.
use colcos::experiment::case1::{self, Case1Config};
use colcos::experiment::case2::{self, Case2Config};
use colcos::experiment::layout::TrailLayout;
use colcos::experiment::summary::{case1_claims, case2_claims};

#[test]
fn case1_claims_hold_for_two_seeds_and_two_layouts() {
    for layout in [TrailLayout::a(), TrailLayout::b()] {
        for seed in [1, 2] {
            let cfg = Case1Config::new(layout.clone(), 20, seed);
            let r = case1::run(&cfg, &|| {}).unwrap();
            let c = case1_claims(&r);
            let counts: Vec<_> = r
                .groups
                .iter()
                .map(|g| (&g.name, &g.counts.per_point, g.counts.timeouts))
                .collect();
            assert!(
                c.all_ok(),
                "layout {} seed {seed}: {c:?}\n{counts:?}",
                layout.name
            );
        }
    }
}

#[test]
fn case2_claims_hold_for_two_seeds() {
    for seed in [1, 2] {
        let cfg = Case2Config::paper(4, seed).unwrap();
        let r = case2::run(&cfg, &|| {}).unwrap();
        let c = case2_claims(&r);
        assert!(c.all_ok(), "seed {seed}: {c:?}");
    }
}
