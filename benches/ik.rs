//! IK per full-pose solve (all solutions within limits, sorted, each checked by FK) on the
//! shipped robots, over 1000 reachable poses from random joints (fixed seed); the numeric
//! fallback on the 7-axis fixture for comparison. Run: `cargo bench --bench ik`.

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::cell::Robot;
use nalgebra::Isometry3;
use std::hint::black_box;

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn poses(robot: &Robot, n: usize) -> Vec<Isometry3<f64>> {
    let mut rng = Lcg(1);
    let limits = robot.limits();
    (0..n)
        .map(|_| {
            let q: Vec<f64> = limits
                .iter()
                .map(|&(lo, hi)| {
                    let (lo, hi) = (lo.max(-std::f64::consts::PI), hi.min(std::f64::consts::PI));
                    lo + (hi - lo) * rng.next()
                })
                .collect();
            robot.fk_tip(&q)
        })
        .collect()
}

fn bench_ik(c: &mut Criterion) {
    let tcp = Isometry3::identity();
    for name in ["abb-irb4600-40-255", "kuka-kr150-2"] {
        let robot = Robot::load(name).unwrap();
        let targets = poses(&robot, 1000);
        let seed = robot.home();
        // 100 % success on these reachable poses is a precondition of the figure.
        assert!(targets.iter().all(|p| robot.ik(p, &tcp, &seed).is_ok()));
        let qs: Vec<Vec<f64>> = targets
            .iter()
            .map(|p| robot.ik(p, &tcp, &seed).unwrap()[0].clone())
            .collect();
        let mut k = 0;
        c.bench_function(&format!("fk_tip/{name}"), |b| {
            b.iter(|| {
                k = (k + 1) % qs.len();
                black_box(robot.fk_tip(black_box(&qs[k])))
            })
        });
        let seed6: [f64; 6] = std::array::from_fn(|j| seed[j]);
        let mut i = 0;
        c.bench_function(&format!("ik6_full_pose/{name}"), |b| {
            b.iter(|| {
                i = (i + 1) % targets.len();
                black_box(robot.ik6(black_box(&targets[i]), &tcp, &seed6)).ok()
            })
        });
        let mut i = 0;
        c.bench_function(&format!("ik_full_pose/{name}"), |b| {
            b.iter(|| {
                i = (i + 1) % targets.len();
                black_box(robot.ik(black_box(&targets[i]), &tcp, &seed)).ok()
            })
        });
    }
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/robots/arm7.urdf"
    );
    let robot = Robot::load(path).unwrap();
    let targets = poses(&robot, 200);
    let seed = robot.home();
    let mut i = 0;
    c.bench_function("ik_numeric_fallback/arm7", |b| {
        b.iter(|| {
            i = (i + 1) % targets.len();
            black_box(robot.ik(black_box(&targets[i]), &tcp, &seed)).ok()
        })
    });
}

criterion_group!(benches, bench_ik);
criterion_main!(benches);
