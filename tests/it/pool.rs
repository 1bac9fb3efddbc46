//! Work spread over a few threads, results in the order of the work: how
//! the random-program generators infer many drawings at once and still
//! report them in the same order on any number of threads.

use std::collections::VecDeque;
use std::sync::Mutex;

/// `f` of every item on `threads` threads (at least one), each item with
/// its result, in the items' order.
pub fn in_order<T: Send, R: Send>(
    items: Vec<T>,
    threads: usize,
    f: impl Fn(&T) -> R + Sync,
) -> Vec<(T, R)> {
    let queue = Mutex::new(items.into_iter().enumerate().collect::<VecDeque<_>>());
    let done = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| {
                loop {
                    let next = queue.lock().map(|mut q| q.pop_front());
                    let Ok(Some((at, item))) = next else {
                        break;
                    };
                    let result = f(&item);
                    if let Ok(mut d) = done.lock() {
                        d.push((at, item, result));
                    }
                }
            });
        }
    });
    let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    done.sort_by_key(|d| d.0);
    done.into_iter().map(|(_, item, r)| (item, r)).collect()
}
