//! The library runs all Symbolica work on one thread: callers on many threads at once all get
//! their results (restricted Symbolica would abort the process if two threads used it), and
//! every job runs on the same dedicated thread, never on the caller's.
#![cfg(feature = "derive")]

use rodcube::derive::{cas, expr::Expr, on_cas_thread};
use std::sync::{Arc, Barrier};
use std::thread;

#[test]
fn concurrent_callers_share_one_cas_thread() {
    const CALLERS: usize = 6;
    let start = Arc::new(Barrier::new(CALLERS));
    let handles: Vec<_> = (0..CALLERS)
        .map(|i| {
            let start = Arc::clone(&start);
            thread::spawn(move || {
                let caller = thread::current().id();
                start.wait();
                let k = i as i128 + 2;
                // d/dx (x^k * sin(x)) at x = 0.3, derived by Symbolica on its thread.
                let (worker, derivative) = on_cas_thread(move || {
                    let e = Expr::parse(&format!("x^{k}*sin(x)")).unwrap();
                    let d = cas::d(&cas::atom(&e), "x");
                    (thread::current().id(), cas::expr(&d))
                })
                .unwrap_or_else(|e| panic!("caller {i}: {e}"));
                let derivative = derivative.unwrap_or_else(|e| panic!("caller {i}: {e}"));
                let x = 0.3f64;
                let got = derivative.eval(&|s| (s == "x").then_some(x));
                let k = k as i32;
                let want = f64::from(k) * x.powi(k - 1) * x.sin() + x.powi(k) * x.cos();
                assert!((got - want).abs() <= 1e-14 * want.abs(), "{got} vs {want}");
                assert_ne!(worker, caller, "the job ran on the calling thread");
                worker
            })
        })
        .collect();
    let workers: Vec<_> = handles.into_iter().map(|h| h.join().unwrap()).collect();
    assert!(
        workers.iter().all(|w| *w == workers[0]),
        "jobs ran on several threads: {workers:?}"
    );
}

#[test]
fn a_panicking_job_does_not_take_the_worker_down() {
    let failed = on_cas_thread(|| -> u32 { panic!("deliberate") });
    assert!(failed.is_err());
    let after = on_cas_thread(|| cas::expr(&cas::d(&cas::var("y"), "y")));
    assert_eq!(after.unwrap().unwrap(), Expr::int(1));
}
