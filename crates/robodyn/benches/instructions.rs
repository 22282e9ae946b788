//! The counting harness of `benchmarks/instructions.sh`: runs one algorithm on one robot of
//! `cases` a given number of times, so that a counting tool (valgrind) run at two repetition
//! counts gives the instructions and floating-point operations of one call by difference; without
//! a count it times each algorithm natively and prints nanoseconds per call.
//!
//! `cargo bench -p robodyn --bench instructions -- [ROBOT ALGORITHM REPETITIONS]`

mod cases;

use cases::{models, Bench, ALGORITHMS};
use std::hint::black_box;
use std::time::Instant;

fn main() {
    // cargo passes --bench; the rest are ours
    let arguments: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let models = models();
    if let [robot, algorithm, repetitions] = &arguments[..] {
        let (_, model, frame) = models
            .iter()
            .find(|(name, ..)| name == robot)
            .unwrap_or_else(|| panic!("unknown robot {robot}"));
        let repetitions: usize = repetitions.parse().expect("a repetition count");
        let mut bench = Bench::new(model, frame);
        for _ in 0..repetitions {
            black_box(bench.run(algorithm));
        }
        return;
    }
    // native time per call: the best of five runs of enough calls for about 20 ms each
    for (robot, model, frame) in &models {
        let mut bench = Bench::new(model, frame);
        for algorithm in ALGORITHMS {
            for _ in 0..10 {
                black_box(bench.run(algorithm));
            }
            let start = Instant::now();
            black_box(bench.run(algorithm));
            let calls = (0.02 / start.elapsed().as_secs_f64().max(1e-7)).clamp(10.0, 1e6) as usize;
            let best = (0..5)
                .map(|_| {
                    let start = Instant::now();
                    for _ in 0..calls {
                        black_box(bench.run(algorithm));
                    }
                    start.elapsed().as_secs_f64() / calls as f64
                })
                .fold(f64::INFINITY, f64::min);
            println!("{robot}\t{algorithm}\t{:.1}", best * 1e9);
        }
    }
}
