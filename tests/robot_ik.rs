//! IK of the shipped robots: round trip on 10 000 random joint vectors per robot, and the
//! failure reasons (out of reach, joint limit, wrist singularity).

use framewright::cell::{IkFailure, IkOptions, Robot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn joints(&mut self, limits: &[(f64, f64)]) -> Vec<f64> {
        limits
            .iter()
            .map(|&(lo, hi)| lo + (hi - lo) * self.next())
            .collect()
    }
}

const ROBOTS: [&str; 2] = ["abb-irb4600-40-255", "kuka-kr150-2"];

fn pose_error(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    (
        (a.translation.vector - b.translation.vector).norm(),
        a.rotation.angle_to(&b.rotation),
    )
}

fn within_limits(robot: &Robot, q: &[f64]) -> bool {
    q.iter()
        .zip(robot.limits())
        .all(|(v, (lo, hi))| *v >= lo && *v <= hi)
}

#[test]
fn round_trip_10000_random_joint_vectors() {
    let tcp = Isometry3::identity();
    for name in ROBOTS {
        let robot = Robot::load(name).unwrap();
        let limits = robot.limits();
        let home = robot.home();
        let mut rng = Lcg(2024);
        let mut original_found = 0;
        for n in 0..10_000 {
            let q = rng.joints(&limits);
            let pose = robot.fk_tip(&q);
            let sols = robot
                .ik(&pose, &tcp, &home)
                .unwrap_or_else(|e| panic!("{name} #{n} q={q:?}: {e}"));
            assert!(!sols.is_empty());
            // Every returned solution is within limits and puts tool0 on the pose.
            for s in &sols {
                assert!(
                    within_limits(&robot, s),
                    "{name} #{n}: {s:?} outside limits"
                );
                let (dp, dr) = pose_error(&robot.fk_tip(s), &pose);
                assert!(
                    dp <= 1e-6 && dr <= 1e-6,
                    "{name} #{n}: {s:?} misses by {dp:.2e} m {dr:.2e} rad"
                );
            }
            // Closest to the seed first.
            let dist = |s: &Vec<f64>| {
                s.iter()
                    .zip(&home)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
            };
            assert!(
                sols.windows(2).all(|w| dist(&w[0]) <= dist(&w[1])),
                "{name} #{n}: not sorted"
            );
            if n % 100 == 0 {
                let seed6: [f64; 6] = std::array::from_fn(|i| home[i]);
                let six = robot.ik6(&pose, &tcp, &seed6).unwrap();
                assert!(
                    six.iter().map(|s| s.to_vec()).eq(sols.iter().cloned()),
                    "{name} #{n}: ik6 differs from ik"
                );
            }
            if sols
                .iter()
                .any(|s| s.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-6))
            {
                original_found += 1;
            }
        }
        // The original joints are among the solutions (all branches and turns are returned).
        assert_eq!(
            original_found, 10_000,
            "{name}: original joints found {original_found} times"
        );
    }
}

#[test]
fn tcp_offset_is_applied() {
    let robot = Robot::load("abb-irb4600-40-255").unwrap();
    let tcp = Isometry3::translation(0.05, -0.02, 0.35);
    let q = [0.4, 0.3, -0.2, 0.6, 0.8, -0.3];
    let pose = robot.fk_tip(&q) * tcp;
    let sols = robot.ik(&pose, &tcp, &q).unwrap();
    assert!(
        sols[0].iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9),
        "{:?}",
        sols[0]
    );
}

#[test]
fn out_of_reach_reports_distance_and_reach() {
    for name in ROBOTS {
        let robot = Robot::load(name).unwrap();
        let pose = Isometry3::from_parts(
            Translation3::new(3.5, 0.4, 1.0),
            UnitQuaternion::from_euler_angles(0.0, std::f64::consts::PI, 0.0),
        );
        match robot.ik(&pose, &Isometry3::identity(), &robot.home()) {
            Err(IkFailure::OutOfReach {
                distance, reach, ..
            }) => {
                assert!(distance > reach, "{name}: {distance} vs {reach}");
                assert!(distance > 2.0 && distance < 4.0, "{name}: {distance}");
            }
            other => panic!("{name}: expected out_of_reach, got {other:?}"),
        }
        let json = serde_json::to_string(
            &robot
                .ik(&pose, &Isometry3::identity(), &robot.home())
                .unwrap_err(),
        )
        .unwrap();
        assert!(
            json.starts_with(r#"{"kind":"out_of_reach","distance":"#),
            "{json}"
        );
        let back: IkFailure = serde_json::from_str(&json).unwrap();
        assert!(matches!(back, IkFailure::OutOfReach { .. }));
    }
}

#[test]
fn random_out_of_reach_poses_give_out_of_reach() {
    // Poses whose wrist centre is 0.05–1 m beyond the reach, in every direction.
    for name in ROBOTS {
        let robot = Robot::load(name).unwrap();
        let mut rng = Lcg(5);
        for _ in 0..2000 {
            let dir =
                Vector3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
            let rot = UnitQuaternion::from_euler_angles(
                rng.next() * 6.0,
                rng.next() * 6.0,
                rng.next() * 6.0,
            );
            // 3.5–4.5 m from the base origin: beyond both robots' reach from either shoulder.
            let r = 3.5 + rng.next();
            let pose = Isometry3::from_parts(Translation3::from(dir * r), rot);
            match robot.ik(&pose, &Isometry3::identity(), &robot.home()) {
                Err(IkFailure::OutOfReach {
                    distance, reach, ..
                }) => assert!(distance > reach),
                other => panic!("{name}: expected out_of_reach, got {other:?}"),
            }
        }
    }
}

#[test]
fn poses_beyond_joint_limits_give_the_joint_and_its_limit() {
    // Joint vectors with one joint pushed beyond a limit: IK either finds another configuration
    // within limits (checked exactly) or reports joint_limit with a value really beyond it.
    for name in ROBOTS {
        let robot = Robot::load(name).unwrap();
        let limits = robot.limits();
        let names: Vec<String> = robot.active_joints().map(|j| j.name.clone()).collect();
        let mut rng = Lcg(99);
        let (mut limit_reports, mut alternatives) = (0, 0);
        for n in 0..4000 {
            let mut q = rng.joints(&limits);
            let j = [0, 1, 2, 4][n % 4]; // joints 1–3 and 5 (4 and 6 have whole turns)
            let (lo, hi) = limits[j];
            let beyond = 0.02 + 0.3 * rng.next();
            q[j] = if rng.next() < 0.5 {
                lo - beyond
            } else {
                hi + beyond
            };
            if hi - lo + 2.0 * beyond >= 2.0 * std::f64::consts::PI {
                continue;
            }
            let pose = robot.fk_tip(&q);
            match robot.ik(&pose, &Isometry3::identity(), &robot.home()) {
                Ok(sols) => {
                    alternatives += 1;
                    for s in sols {
                        assert!(within_limits(&robot, &s));
                        let (dp, dr) = pose_error(&robot.fk_tip(&s), &pose);
                        assert!(dp <= 1e-6 && dr <= 1e-6);
                    }
                }
                Err(IkFailure::JointLimit {
                    joint,
                    value,
                    limit,
                    excess,
                }) => {
                    limit_reports += 1;
                    let k = names.iter().position(|x| *x == joint).unwrap();
                    let (lo, hi) = limits[k];
                    assert!(
                        value < lo || value > hi,
                        "{name}: {joint}={value} is within [{lo}, {hi}]"
                    );
                    assert!(limit == lo || limit == hi);
                    assert!((excess - (value - limit).abs()).abs() < 1e-12);
                }
                Err(other) => {
                    panic!("{name} q={q:?}: expected joint_limit or a solution, got {other}")
                }
            }
        }
        assert!(
            limit_reports > 200,
            "{name}: only {limit_reports} joint_limit reports"
        );
        assert!(alternatives > 0);
    }
}

#[test]
fn a_pose_only_reachable_beyond_a_limit_names_that_joint() {
    // KR 150-2: A2 is limited to ≤ 0 (upper arm not past horizontal forward). The stretched arm
    // pointing up at 30° needs A2 = +0.52 in every configuration that reaches that far.
    let robot = Robot::load("kuka-kr150-2").unwrap();
    let q = [0.0, 0.52, 0.0, 0.0, 0.3, 0.0];
    let pose = robot.fk_tip(&q);
    match robot.ik(&pose, &Isometry3::identity(), &robot.home()) {
        Err(IkFailure::JointLimit {
            joint,
            value,
            limit,
            ..
        }) => {
            assert_eq!(joint, "joint_a2");
            assert_eq!(limit, 0.0);
            assert!((value - 0.52).abs() < 1e-6, "{value}");
        }
        other => panic!("expected joint_limit, got {other:?}"),
    }
}

#[test]
fn wrist_singularity() {
    let robot = Robot::load("abb-irb4600-40-255").unwrap();
    let tcp = Isometry3::identity();
    // Exactly singular (joint 5 = 0): solutions exist; the free wrist angle comes from the seed.
    let q = [0.2, 0.3, -0.4, 0.7, 0.0, -0.2];
    let pose = robot.fk_tip(&q);
    let seed = [0.2, 0.3, -0.4, 0.5, 0.0, 0.0];
    let sols = robot.ik(&pose, &tcp, &seed).unwrap();
    let (dp, dr) = pose_error(&robot.fk_tip(&sols[0]), &pose);
    assert!(dp < 1e-9 && dr < 1e-9);
    assert!((sols[0][3] - 0.5).abs() < 1e-9, "{:?}", sols[0]);
    // With a required wrist margin, the near-singular configuration is dropped and the others
    // (wrist angles 0.51–0.95 rad for this pose) are kept ...
    let q = [0.2, 0.3, -0.4, 0.7, 0.01, -0.2];
    let pose = robot.fk_tip(&q);
    let options = IkOptions {
        wrist_margin: 0.05,
        ..IkOptions::default()
    };
    let sols = robot.ik_with(&pose, &tcp, &seed, &options).unwrap();
    assert!(sols.iter().all(|s| s[4].abs() >= 0.05), "{sols:?}");
    // ... and when no configuration keeps the margin, the best wrist angle found is reported.
    let options = IkOptions {
        wrist_margin: 1.0,
        ..IkOptions::default()
    };
    match robot.ik_with(&pose, &tcp, &seed, &options) {
        Err(IkFailure::WristSingularity { margin, required }) => {
            assert!(margin > 0.9 && margin < 1.0, "{margin}");
            assert_eq!(required, 1.0);
        }
        other => panic!("expected wrist_singularity, got {other:?}"),
    }
}

#[test]
fn non_finite_pose_is_refused() {
    let robot = Robot::load("kuka-kr150-2").unwrap();
    let pose = Isometry3::translation(f64::NAN, 0.0, 1.0);
    assert_eq!(
        robot.ik(&pose, &Isometry3::identity(), &robot.home()),
        Err(IkFailure::InvalidPose)
    );
}

#[test]
fn near_singular_wrists_round_trip() {
    // Both formulas meet at the switch to the singular branch; every wrist angle must work.
    for name in ROBOTS {
        let robot = Robot::load(name).unwrap();
        for (k, q5) in [
            0.0, 1e-12, 1e-10, 1e-9, 3e-8, 1e-7, 2e-7, 1e-6, 1e-5, -1e-8, -1e-6,
        ]
        .into_iter()
        .enumerate()
        {
            let q = [0.3 - 0.1 * k as f64, -0.5, 0.6, 0.4, q5, -0.7];
            let pose = robot.fk_tip(&q);
            let sols = robot
                .ik(&pose, &Isometry3::identity(), &robot.home())
                .unwrap_or_else(|e| panic!("{name} q5={q5}: {e}"));
            for s in &sols {
                let (dp, dr) = pose_error(&robot.fk_tip(s), &pose);
                assert!(dp <= 1e-6 && dr <= 1e-6, "{name} q5={q5}: {dp} {dr}");
            }
        }
    }
}

/// `ik_closest` is `ik`'s first solution, computed without listing the others: the same
/// joint values bit for bit, or the same failure, on reachable, unreachable and
/// limit-bound poses from random seeds, with and without a TCP offset (both shipped robots
/// and the numeric fallback of the 7-axis fixture).
#[test]
fn ik_closest_is_the_first_of_all_solutions() {
    let arm7 = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/robots/arm7.urdf"
    );
    let offset = Isometry3::from_parts(
        Translation3::new(0.05, -0.02, 0.31),
        UnitQuaternion::from_euler_angles(0.1, -0.4, 0.7),
    );
    for (name, n) in [(ROBOTS[0], 4000), (ROBOTS[1], 4000), (arm7, 40)] {
        let robot = Robot::load(name).unwrap();
        // Joints drawn over up to two turns beyond the usual range, so several whole-turn
        // copies of the wrist joints fit and the seed decides among them.
        let limits: Vec<(f64, f64)> = robot
            .limits()
            .iter()
            .map(|&(lo, hi)| (lo.max(-7.0), hi.min(7.0)))
            .collect();
        let mut rng = Lcg(77);
        let (mut solved, mut failed) = (0, 0);
        for k in 0..n {
            let q = rng.joints(&limits);
            let mut pose = robot.fk_tip(&q);
            if k % 5 == 4 {
                // Some poses pushed out of reach or towards the limits.
                pose.translation.vector *= 1.0 + rng.next();
            }
            let seed = rng.joints(&limits);
            for tcp in [Isometry3::identity(), offset] {
                let target = pose * tcp;
                match (
                    robot.ik(&target, &tcp, &seed),
                    robot.ik_closest(&target, &tcp, &seed),
                ) {
                    (Ok(all), Ok(first)) => {
                        assert_eq!(all[0], first, "{name} #{k}");
                        solved += 1;
                    }
                    (Err(a), Err(b)) => {
                        assert_eq!(a.to_string(), b.to_string(), "{name} #{k}");
                        failed += 1;
                    }
                    (a, b) => panic!("{name} #{k}: ik {a:?} but ik_closest {b:?}"),
                }
            }
        }
        assert!(
            solved > n / 2 && failed > 0,
            "{name}: {solved} solved, {failed} failed"
        );
    }
}

/// Whether two lists of link poses (`Robot::fk_all`) are one arm shape: whole turns of a
/// joint give the same.
fn same_shape(a: &[Isometry3<f64>], b: &[Isometry3<f64>]) -> bool {
    a.iter().zip(b).all(|(x, y)| {
        let (dp, dr) = pose_error(x, y);
        dp < 1e-9 && dr < 1e-9
    })
}

#[test]
fn ik_branches_are_the_arm_shapes_of_all_solutions() {
    for name in ROBOTS {
        let robot = Robot::load(name).unwrap();
        // Wrist joints' ranges exceed a turn: `ik` gives whole-turn copies `ik_branches` drops.
        let limits = robot.limits();
        let mut rng = Lcg(4242);
        let tcp = Isometry3::translation(0.0, 0.1, 0.3);
        let mut copies_dropped = 0;
        for k in 0..2000 {
            let q = rng.joints(&limits);
            let mut pose = robot.fk_tip(&q) * tcp;
            if k % 7 == 6 {
                pose.translation.vector *= 1.5;
            }
            let seed = rng.joints(&limits);
            match (
                robot.ik(&pose, &tcp, &seed),
                robot.ik_branches(&pose, &tcp, &seed),
            ) {
                (Ok(all), Ok(branches)) => {
                    assert!(
                        branches.len() <= 8,
                        "{name} #{k}: {} branches",
                        branches.len()
                    );
                    let all: Vec<_> = all.iter().map(|s| robot.fk_all(s)).collect();
                    let branches: Vec<_> = branches.iter().map(|s| robot.fk_all(s)).collect();
                    // Each solution's shape is a branch's, and each branch is a solution's.
                    for (i, s) in all.iter().enumerate() {
                        assert!(
                            branches.iter().any(|b| same_shape(s, b)),
                            "{name} #{k}: solution {i} has no branch"
                        );
                    }
                    for b in &branches {
                        assert!(all.iter().any(|s| same_shape(s, b)), "{name} #{k}");
                    }
                    copies_dropped += all.len() - branches.len();
                }
                (Err(_), Err(_)) => {}
                (a, b) => panic!("{name} #{k}: ik {a:?} but ik_branches {b:?}"),
            }
        }
        assert!(copies_dropped > 0, "{name}: no whole-turn copies to drop");
    }
}
