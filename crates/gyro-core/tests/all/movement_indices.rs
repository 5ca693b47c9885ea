//! The movement indices the pipeline publishes are the output samples that bound each
//! movement: their times (less the filter delay) are the movement's times, and the angle
//! between them is the movement's angle. Hosts index their output series with them.

use crate::common::{run, BenchSpec, Profile, Rng};
use gyro_core::{Compensation, Config, Event};

#[test]
fn indices_are_the_output_samples_that_bound_each_movement() {
    let mut checked = 0;
    for seed in 1..=8 {
        for compensation in [
            Compensation::None,
            Compensation::Paper,
            Compensation::Kalman,
        ] {
            let mut rng = Rng::new(seed);
            let profile = Profile::bench(&mut rng, &BenchSpec::default());
            let samples = profile.samples(1000.0, 0.3, 0.05, &mut rng);
            let config = Config {
                compensation,
                ..Config::default()
            };
            let r = run(&config, &samples, 1000.0);
            let delay_s = r.pipeline.filter_delay_s();
            let mut started = Vec::new();
            for out in &r.outputs {
                if let Some(Event::MovementStarted {
                    start_time_s,
                    start_index,
                }) = out.event
                {
                    let at = &r.outputs[start_index as usize];
                    assert!((at.time_s - delay_s - start_time_s).abs() < 1e-6);
                    started.push(start_index);
                }
            }
            assert!(!r.movements.is_empty(), "seed {seed}: no movement");
            for (confirmed_at, m) in &r.movements {
                let (start, end) = (m.start_index as usize, m.end_index as usize);
                assert!(
                    start < end && end <= *confirmed_at,
                    "{m:?} at {confirmed_at}"
                );
                assert!(started.contains(&m.start_index), "{m:?}");
                let (a, b) = (&r.outputs[start], &r.outputs[end]);
                assert!((a.time_s - delay_s - m.start_time_s).abs() < 1e-6, "{m:?}");
                assert!((b.time_s - delay_s - m.end_time_s).abs() < 1e-6, "{m:?}");
                // The raw angle is held at rest: between the bounding samples it moves by
                // exactly the movement's raw angle.
                let moved = b.raw_angle_deg - a.raw_angle_deg;
                assert!((moved - m.raw_angle_deg).abs() < 1e-3, "{moved} vs {m:?}");
                checked += 1;
            }
        }
    }
    assert!(checked > 50, "{checked}");
}
