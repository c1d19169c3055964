//! The library runs all Symbolica work on one thread: callers on many threads at once all get
//! their results (restricted Symbolica would abort the process if two threads used it), and
//! every job runs on the same dedicated thread, never on the caller's; a job there that waits
//! on another job there gets an error instead of waiting for ever.
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

#[test]
fn a_job_that_waits_on_another_job_gets_an_error_not_a_hang() {
    // The worker runs one job at a time: a job that queued a second and waited for it would
    // wait for ever (holding the inter-process lock); both ways in refuse instead.
    let nested = on_cas_thread(|| {
        let call = on_cas_thread(|| 1).map_err(|e| e.to_string());
        let derive = rodcube::derive::derive_all(&[]).map_err(|e| e.to_string());
        (call, derive.map(|v| v.len()))
    })
    .expect("the outer job runs");
    assert!(nested.0.is_err(), "nested on_cas_thread: {:?}", nested.0);
    assert!(nested.1.is_err(), "nested derive_all: {:?}", nested.1);
    let after = on_cas_thread(|| cas::expr(&cas::d(&cas::var("y"), "y")));
    assert_eq!(after.unwrap().unwrap(), Expr::int(1));
}
