//! Screen <-> camera calibration on the twin, whose camera is known: fiducials shown through the
//! frame stream are read back over SwarmCon, the homography and heading are fitted, and the robots'
//! poses through the calibration land within a millimetre of where they truly are.
use colcos_bridge::calibrate::{RigCalibration, ScreenCalibration};
use colcos_bridge::calibrate::{ScreenRunOptions, calibrate_screen};
use colcos_bridge::twin::{CameraModel, Noise};
use colcos_bridge::{SourceOptions, open_pose_source};
use colcos_testkit::scenarios::parked;
use colcos_testkit::twin::TwinRun;

#[test]
fn the_screen_calibration_recovers_the_camera_within_a_millimetre() {
    let sc = parked(&[[0.72, 0.40, 20.0], [0.3, 0.25, 0.0], [1.1, 0.6, 90.0]])
        .build()
        .unwrap();
    let size = [sc.spec.screen.size[0] as f64, sc.spec.screen.size[1] as f64];
    let camera = CameraModel::lab(size);
    let mut run = TwinRun::start(&sc, Some(camera), 0.0, 0.0, 30.0);
    let opts = ScreenRunOptions {
        camera_height: camera.position[2],
        marker_height: camera.marker_height,
        heading_robot: Some(0),
        ..ScreenRunOptions::default()
    };
    let started = std::time::Instant::now();
    let (cal, sightings) = calibrate_screen(&mut run.rig, &sc, &opts).unwrap();
    let took = started.elapsed().as_secs_f64();
    assert_eq!(sightings.len(), 4 + 24);
    assert!(cal.inliers >= 24, "{cal:?}");

    // Against the truth, noise-free, over the arena: markers at their height, headings all round.
    let map = cal.map();
    let exact = CameraModel {
        noise_px: 0.0,
        ..camera
    };
    let mut noise = Noise::new(0);
    let (mut ss, mut n, mut worst_heading) = (0.0, 0, 0.0f64);
    for i in 0..12 {
        for j in 0..7 {
            let (x, y) = (0.05 + i as f64 * 0.12, 0.05 + j as f64 * 0.115);
            let h = (i * 7 + j) as f64 * 0.7 - 3.0;
            let (tx, ty, yaw) = exact.see_marker(x, y, h, &mut noise).unwrap();
            let (bx, by, bh) = map.to_sim(tx, ty, yaw).unwrap();
            ss += (bx - x).powi(2) + (by - y).powi(2);
            n += 1;
            let dh = (bh - h + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            worst_heading = worst_heading.max(dh.abs());
        }
    }
    let rms_mm = (ss / n as f64).sqrt() * 1e3;
    eprintln!(
        "screen calibration on the twin: fiducial reprojection {:.3} mm RMS ({} of {} kept), robot positions {rms_mm:.3} mm RMS against the truth, heading sign {} offset {:.2} deg (fit spread {:.2} deg), worst heading error {:.2} deg; took {took:.1} s",
        cal.rms_mm,
        cal.inliers,
        cal.fiducials,
        cal.heading_sign,
        cal.heading_offset_deg,
        cal.heading_rms_deg,
        worst_heading.to_degrees()
    );
    assert!(cal.rms_mm < 1.0, "{cal:?}");
    assert!(rms_mm < 1.0, "{rms_mm} mm");
    assert!(
        worst_heading.to_degrees() < 3.0,
        "{}",
        worst_heading.to_degrees()
    );

    // Without the parallax correction the same markers would be off by up to ~2 cm.
    let flat = colcos_bridge::geometry::ScreenMap {
        marker_height: 0.0,
        ..map
    };
    let (tx, ty, yaw) = exact.see_marker(1.35, 0.75, 0.0, &mut noise).unwrap();
    let (fx, fy, _) = flat.to_sim(tx, ty, yaw).unwrap();
    assert!((fx - 1.35).hypot(fy - 0.75) > 0.01);

    // The file round-trips, and the bridge's pose source applies it at the edge.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("screen.json");
    cal.save(&path).unwrap();
    let back = ScreenCalibration::load(&path).unwrap();
    assert_eq!(
        (back.resolution, back.inliers),
        (cal.resolution, cal.inliers)
    );
    let (a, b) = (
        back.map().to_sim(0.3, 0.2, 10.0),
        map.to_sim(0.3, 0.2, 10.0),
    );
    let (a, b) = (a.unwrap(), b.unwrap());
    assert!((a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12 && (a.2 - b.2).abs() < 1e-12);
    let through_file = |s: &mut colcos_sim::scenario::ScenarioSpec| {
        s.rig.screen_calibration = Some(path.display().to_string())
    };
    let calibrated = parked(&[[0.72, 0.40, 20.0]])
        .with(through_file)
        .build()
        .unwrap();
    let loaded = RigCalibration::load(&calibrated).unwrap();
    let opts = SourceOptions::new(loaded.frame_transform(&calibrated));
    let mut source = open_pose_source(&format!("swarmcon://{}", run.tracker_addr), &opts).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(400));
    let snapshot = source.poll().expect("poses through the calibration");
    let twin = run.stop();
    let truth = twin.arena().poses();
    for p in snapshot.poses.iter().filter(|p| p.fresh) {
        let t = truth[p.id as usize];
        let d = (p.pose.pos - t.pos).length();
        // The tracker model's own 1 mm noise and the camera's 0.25 px on top of the calibration.
        assert!(d < 0.006, "robot {}: {d} m from its true position", p.id);
    }

    // A calibration of another panel is refused, naming both resolutions.
    let other = parked(&[[0.72, 0.4, 0.0]])
        .with(through_file)
        .with(|s| s.screen.resolution = [1920, 1080])
        .build()
        .unwrap();
    let err = RigCalibration::load(&other).unwrap_err().to_string();
    assert!(
        err.contains("3840x2160") && err.contains("1920x1080"),
        "{err}"
    );
}
