//! Which case-II run the figures show, and which moments of it Fig. 7 shows, chosen from the data:
//! the run that goes through aggregation, an alarm, dispersion and (best) aggregation again, and the
//! moments that show each of them.
use super::case2::{Case2Result, Case2Run};
use colcos_sim::metrics::PhaseKind;

/// One moment of a run shown in Fig. 7.
#[derive(Clone, Debug, PartialEq)]
pub struct Moment {
    /// Index of the S(t) sample.
    pub sample: usize,
    /// Its time, s.
    pub time: f32,
    /// What it shows: "start", "aggregated", "alarm", "dispersion", "re-aggregation", "end", or the
    /// phase of an in-between moment.
    pub what: &'static str,
}

/// How much of the paper's story run `run` tells: 0 no alarm (or one from the start), 1 an alarm
/// after an aggregation phase, 2 the same with an aggregation phase again after the alarm.
fn story(run: &Case2Run) -> usize {
    let p = &run.phases;
    let Some(k) = (1..p.len()).find(|&k| p[k].kind == PhaseKind::Dispersion) else {
        return 0;
    };
    if p[k + 1..]
        .iter()
        .any(|q| q.kind == PhaseKind::Aggregation && q.end - q.start >= 2.0)
    {
        2
    } else {
        1
    }
}

/// The run the figures show: the first with the fullest story (aggregation, alarm, dispersion,
/// aggregation again), run 0 when no run has an alarm.
pub fn featured_run(r: &Case2Result) -> usize {
    let best = r.runs.iter().map(story).max().unwrap_or(0);
    r.runs.iter().position(|x| story(x) == best).unwrap_or(0)
}

fn argmin(s: &[f32], from: usize, to: usize) -> usize {
    (from..=to)
        .min_by(|&a, &b| s[a].total_cmp(&s[b]))
        .unwrap_or(from)
}

fn argmax(s: &[f32], from: usize, to: usize) -> usize {
    (from..=to)
        .max_by(|&a, &b| s[a].total_cmp(&s[b]))
        .unwrap_or(from)
}

/// The phase of sample `k` in words.
pub fn phase_word(run: &Case2Run, k: usize) -> &'static str {
    if run.alarm.get(k).copied().unwrap_or(false) {
        "dispersion"
    } else {
        "aggregation"
    }
}

/// Six distinct moments of `run` in time order. With an alarm after an aggregation phase: the start,
/// the tightest aggregation before the alarm, the alarm, the widest dispersion, the tightest
/// aggregation after it (or the end of the dispersion) and the end of the run. Moments closer than
/// `min_gap` seconds to an earlier one are dropped and the widest gaps filled, so the six differ.
pub fn key_moments(run: &Case2Run, min_gap: f32) -> Vec<Moment> {
    let (t, s, p) = (&run.times, &run.s, &run.phases);
    let last = t.len().saturating_sub(1);
    let mut picks: Vec<(usize, &'static str)> = vec![(0, "start")];
    if let Some(k) = (1..p.len()).find(|&k| p[k].kind == PhaseKind::Dispersion) {
        let (agg, disp) = (p[k - 1], p[k]);
        picks.push((argmin(s, agg.first, agg.last), "aggregated"));
        picks.push((disp.first, "alarm"));
        picks.push((argmax(s, disp.first, disp.last), "dispersion"));
        match p.get(k + 1) {
            Some(next) => picks.push((argmin(s, next.first, next.last), "re-aggregation")),
            None => picks.push((disp.last, "dispersion")),
        }
    }
    picks.push((last, "end"));
    let mut kept: Vec<(usize, &'static str)> = Vec::new();
    for (i, what) in picks {
        if kept.last().is_none_or(|&(j, _)| t[i] - t[j] >= min_gap) {
            kept.push((i, what));
        }
    }
    // Fill the widest gaps with their midpoints until there are six.
    while kept.len() < 6 && last > 0 {
        let Some(g) = (1..kept.len())
            .max_by(|&a, &b| (kept[a].0 - kept[a - 1].0).cmp(&(kept[b].0 - kept[b - 1].0)))
        else {
            kept.push((last, "end"));
            continue;
        };
        let (a, b) = (kept[g - 1].0, kept[g].0);
        if b - a < 2 {
            break;
        }
        let mid = (a + b) / 2;
        kept.insert(g, (mid, phase_word(run, mid)));
    }
    kept.into_iter()
        .map(|(i, what)| Moment {
            sample: i,
            time: t[i],
            what,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use colcos_sim::metrics::phases;

    fn run_with(alarm_from: usize, alarm_to: usize) -> Case2Run {
        let n = 900;
        let times: Vec<f32> = (0..n).map(|k| k as f32 * 0.1).collect();
        let alarm: Vec<bool> = (0..n)
            .map(|k| (alarm_from..alarm_to).contains(&k))
            .collect();
        // S falls to 0.2 by 20 s, rises during the alarm, falls again after.
        let s: Vec<f32> = (0..n)
            .map(|k| {
                if k < alarm_from {
                    (1.2 - k as f32 * 0.005).max(0.2)
                } else if k < alarm_to {
                    0.2 + (k - alarm_from) as f32 * 0.01
                } else {
                    (0.2 + (alarm_to - alarm_from) as f32 * 0.01 - (k - alarm_to) as f32 * 0.01)
                        .max(0.3)
                }
            })
            .collect();
        Case2Run {
            phases: phases(&times, &alarm),
            times,
            s,
            alarm,
            paths: Vec::new(),
            roles: Vec::new(),
            aggregation_fall: 0.0,
            alarm_rise: None,
        }
    }

    #[test]
    fn a_full_story_gives_six_distinct_moments_in_order() {
        let run = run_with(400, 600);
        let m = key_moments(&run, 1.0);
        let what: Vec<_> = m.iter().map(|m| m.what).collect();
        assert_eq!(
            what,
            [
                "start",
                "aggregated",
                "alarm",
                "dispersion",
                "re-aggregation",
                "end"
            ]
        );
        assert!(m.windows(2).all(|w| w[1].time - w[0].time >= 1.0));
        assert_eq!(m[2].time, 40.0);
        assert!(run.alarm[m[3].sample] && !run.alarm[m[4].sample]);
    }

    #[test]
    fn a_run_without_alarm_still_gives_six_distinct_aggregation_moments() {
        let run = run_with(2000, 2000);
        let m = key_moments(&run, 1.0);
        assert_eq!(m.len(), 6);
        assert!(m.windows(2).all(|w| w[1].time > w[0].time));
        assert!(m[1..5].iter().all(|m| m.what == "aggregation"));
    }

    #[test]
    fn an_alarm_at_the_very_end_keeps_six_moments() {
        let run = run_with(889, 900);
        let m = key_moments(&run, 1.0);
        assert_eq!(m.len(), 6);
        assert!(m.iter().any(|m| m.what == "alarm"));
        assert!(m.windows(2).all(|w| w[1].time > w[0].time));
    }

    #[test]
    fn the_featured_run_is_the_one_with_the_fullest_story() {
        let cfg = crate::cmd::experiment::case2::Case2Config::paper(1, 1).unwrap();
        let r = Case2Result {
            config: cfg,
            runs: vec![run_with(2000, 2000), run_with(889, 900), run_with(400, 600)],
            wall_seconds: 0.0,
        };
        assert_eq!(featured_run(&r), 2);
    }
}
