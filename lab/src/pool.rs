//! The lab's one work pool: a fixed number of threads taking items in order, for the work
//! that runs external programs or long simulations side by side (synthesis flows, placements,
//! explore's candidates, the two gyros of a reproduction).
//!
//! Items are taken in the order given, so a caller that knows its items' lengths puts the
//! longest first: on two cores the last long item then does not run alone at the end.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

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
}
