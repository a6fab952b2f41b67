//! The lab's one work pool: a fixed number of threads taking items in order, for the work
//! that runs external programs or long simulations side by side (synthesis flows, placements,
//! explore's candidates, the two gyros of a reproduction).
//!
//! Items are taken in the order given, so a caller that knows its items' lengths puts the
//! longest first: on two cores the last long item then does not run alone at the end.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};

/// Runs `work` on every item on at most `jobs` threads (at least one) and gives the results in
/// the items' order. After an item fails no further item starts; the items already running
/// finish.
///
/// # Errors
/// The error of the first item in the items' order that failed. Every item before it was
/// taken before it and so has run: the error is the same whatever the threads' timing.
pub fn try_map<T, R, E>(
    items: &[T],
    jobs: usize,
    work: impl Fn(&T) -> Result<R, E> + Sync,
) -> Result<Vec<R>, E>
where
    T: Sync,
    R: Send,
    E: Send,
{
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let results: Mutex<Vec<Option<Result<R, E>>>> =
        Mutex::new((0..items.len()).map(|_| None).collect());
    let work = &work;
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, items.len().max(1)) {
            scope.spawn(|| loop {
                if stop.load(Ordering::SeqCst) {
                    break;
                }
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(item) = items.get(i) else {
                    break;
                };
                let result = work(item);
                if result.is_err() {
                    stop.store(true, Ordering::SeqCst);
                }
                results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(result);
            });
        }
    });
    let mut out = Vec::with_capacity(items.len());
    for result in results.into_inner().unwrap_or_else(|e| e.into_inner()) {
        match result {
            Some(Ok(r)) => out.push(r),
            Some(Err(e)) => return Err(e),
            // Not started: an earlier item failed, and its error was returned above.
            None => unreachable!("an item after a failure is only skipped once one failed"),
        }
    }
    Ok(out)
}

/// [`try_map`] for work that cannot fail.
pub fn map<T: Sync, R: Send>(items: &[T], jobs: usize, work: impl Fn(&T) -> R + Sync) -> Vec<R> {
    match try_map(items, jobs, |item| {
        Ok::<R, std::convert::Infallible>(work(item))
    }) {
        Ok(results) => results,
        Err(never) => match never {},
    }
}

/// Runs `work(i)` for every `i` in `0..count` on at most `jobs` threads (at least one) and
/// hands each result to `sink` in index order as soon as it and all before it are done. At
/// most `2·jobs` results wait for the sink (a thread does not start an item further ahead),
/// so memory does not grow with `count`. When the sink fails, no further item starts and the
/// error is returned once the running ones end.
///
/// # Errors
/// The sink's first error.
pub fn ordered<R: Send, E>(
    count: u64,
    jobs: usize,
    work: impl Fn(u64) -> R + Sync,
    mut sink: impl FnMut(u64, R) -> Result<(), E>,
) -> Result<(), E> {
    let jobs = jobs.max(1);
    let window = 2 * jobs as u64;
    let next = AtomicU64::new(0);
    let stop = AtomicBool::new(false);
    // The results waiting for the sink, and the index the sink takes next.
    let state = Mutex::new((std::collections::BTreeMap::<u64, R>::new(), 0u64));
    let changed = Condvar::new();
    let lock = || state.lock().unwrap_or_else(|e| e.into_inner());
    let work = &work;
    std::thread::scope(|scope| {
        for _ in 0..(jobs as u64).min(count) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                if i >= count {
                    break;
                }
                let mut guard = lock();
                while i >= guard.1 + window && !stop.load(Ordering::SeqCst) {
                    guard = changed.wait(guard).unwrap_or_else(|e| e.into_inner());
                }
                drop(guard);
                if stop.load(Ordering::SeqCst) {
                    break;
                }
                let result = work(i);
                lock().0.insert(i, result);
                changed.notify_all();
            });
        }
        let mut outcome = Ok(());
        for i in 0..count {
            let mut guard = lock();
            let result = loop {
                if let Some(r) = guard.0.remove(&i) {
                    break r;
                }
                guard = changed.wait(guard).unwrap_or_else(|e| e.into_inner());
            };
            drop(guard);
            if let Err(e) = sink(i, result) {
                outcome = Err(e);
                stop.store(true, Ordering::SeqCst);
                changed.notify_all();
                break;
            }
            lock().1 = i + 1;
            changed.notify_all();
        }
        outcome
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_in_the_items_order_whatever_the_threads() {
        let items: Vec<u64> = (0..50).collect();
        for jobs in [0, 1, 2, 7, 100] {
            let squares = map(&items, jobs, |x| {
                // Later items finish first on several threads.
                std::thread::sleep(std::time::Duration::from_micros(50 - x));
                x * x
            });
            assert_eq!(squares, items.iter().map(|x| x * x).collect::<Vec<_>>());
        }
    }

    #[test]
    fn the_first_failure_in_order_is_returned_and_no_item_starts_after_it() {
        let items: Vec<usize> = (0..40).collect();
        let started = AtomicUsize::new(0);
        let result = try_map(&items, 2, |&i| {
            started.fetch_add(1, Ordering::SeqCst);
            if i == 5 || i == 6 {
                Err(format!("item {i}"))
            } else {
                std::thread::sleep(std::time::Duration::from_millis(2));
                Ok(i)
            }
        });
        assert_eq!(result, Err("item 5".to_string()));
        // Item 5 and at most the one the other thread had taken, plus those before.
        assert!(started.load(Ordering::SeqCst) <= 8, "{started:?}");
    }

    #[test]
    fn no_items_give_no_results() {
        assert!(map(&[] as &[u8], 4, |x| *x).is_empty());
    }

    #[test]
    fn ordered_hands_results_in_order_with_a_bounded_backlog() {
        for jobs in [1, 2, 5] {
            let mut seen = Vec::new();
            let running = AtomicU64::new(0);
            let emitted = AtomicU64::new(0);
            ordered(
                40,
                jobs,
                |i| {
                    // Never further ahead of the sink than the window.
                    assert!(i < emitted.load(Ordering::SeqCst) + 2 * jobs as u64 + 1);
                    running.fetch_add(1, Ordering::SeqCst);
                    std::thread::sleep(std::time::Duration::from_micros((i * 7919) % 300));
                    i * i
                },
                |i, r| {
                    assert_eq!(r, i * i);
                    seen.push(i);
                    emitted.store(i + 1, Ordering::SeqCst);
                    Ok::<(), ()>(())
                },
            )
            .unwrap();
            assert_eq!(seen, (0..40).collect::<Vec<_>>());
        }
        let mut taken = 0;
        let err = ordered(
            100,
            2,
            |i| i,
            |i, _| {
                taken += 1;
                if i == 5 {
                    Err(i)
                } else {
                    Ok(())
                }
            },
        );
        assert_eq!((err, taken), (Err(5), 6));
    }
}
