//! The studio's work on programs: a small pool of worker threads, each with
//! the stop flag that its derivations read, and the clients' sessions, each
//! with its own sequence numbers, so that a newer request of one page stops
//! and replaces that page's older ones without touching another page's.
//!
//! Owns: how many programs run at once, stopping them, and which answers are
//! stale. Must not speak HTTP (`server` does) or run programs itself
//! (`protocol` does).

use super::protocol::DragSession;
use std::collections::HashMap;
use std::future::Future;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use tokio::sync::{OwnedSemaphorePermit, Semaphore, watch};

/// The most workers a pool may have.
pub const MAX_WORKERS: usize = 8;

/// A worker's place and its stop flag: `derive::Limits::cancel` is a
/// `&'static AtomicBool` (the limits are `Copy` and shared with the command
/// line), so each pool makes its places once, for the life of the process
/// (a few bytes a worker; a studio makes two pools), and a job borrows its
/// place's flag while it runs. `owner` names the job holding the place (0:
/// none), so that stopping a job that already ended never stops the next
/// job in its place.
struct Place {
    flag: AtomicBool,
    owner: Mutex<u64>,
}

/// Numbers the jobs, so that a place knows which job holds it.
static JOBS: AtomicU64 = AtomicU64::new(1);

/// A pool of worker places: at most `size` programs run at once.
pub struct Pool {
    permits: Arc<Semaphore>,
    free: Arc<Mutex<Vec<&'static Place>>>,
}

/// A worker place held by one job while it runs on its thread; given back
/// when dropped (after the job's work ends, whatever happened to its request).
struct Lease {
    place: &'static Place,
    job: u64,
    free: Arc<Mutex<Vec<&'static Place>>>,
    _permit: OwnedSemaphorePermit,
}

impl Drop for Lease {
    fn drop(&mut self) {
        *self
            .place
            .owner
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = 0;
        self.free
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(self.place);
    }
}

/// Stops job `job` if it still holds place `place`.
fn stop(place: &Place, job: u64) {
    let owner = place.owner.lock().unwrap_or_else(PoisonError::into_inner);
    if *owner == job {
        place.flag.store(true, Ordering::SeqCst);
    }
}

/// Stops the job when the request waiting for it goes away (the client
/// closed the connection, or the server dropped it), unless it was disarmed.
struct StopOnDrop {
    place: &'static Place,
    job: u64,
    armed: bool,
}

impl Drop for StopOnDrop {
    fn drop(&mut self) {
        if self.armed {
            stop(self.place, self.job);
        }
    }
}

impl Pool {
    /// A pool of `size` workers (at least 1, at most [`MAX_WORKERS`]).
    pub fn new(size: usize) -> Pool {
        let size = size.clamp(1, MAX_WORKERS);
        Pool {
            permits: Arc::new(Semaphore::new(size)),
            free: Arc::new(Mutex::new(
                (0..size)
                    .map(|_| {
                        &*Box::leak(Box::new(Place {
                            flag: AtomicBool::new(false),
                            owner: Mutex::new(0),
                        }))
                    })
                    .collect(),
            )),
        }
    }

    /// A pool sized for this machine: as many workers as cores, 2 to 4.
    pub fn for_machine() -> Pool {
        let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
        Pool::new(cores.clamp(2, 4))
    }

    async fn lease(&self) -> Option<Lease> {
        let permit = Arc::clone(&self.permits).acquire_owned().await.ok()?;
        let place = self
            .free
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .pop()?;
        let job = JOBS.fetch_add(1, Ordering::Relaxed);
        {
            let mut owner = place.owner.lock().unwrap_or_else(PoisonError::into_inner);
            *owner = job;
            place.flag.store(false, Ordering::SeqCst);
        }
        Some(Lease {
            place,
            job,
            free: Arc::clone(&self.free),
            _permit: permit,
        })
    }

    /// Runs `work` on a worker thread with its stop flag, once a worker is
    /// free. `None` when `stopped` finished first (the job was superseded):
    /// before it started, it never starts; while it runs, its flag is set and
    /// the job ends at its next derivation step (its worker stays taken until
    /// then, so the pool bounds the work really running). Dropping the
    /// returned future stops the job the same way.
    pub async fn run<T: Send + 'static>(
        &self,
        stopped: impl Future<Output = ()>,
        work: impl FnOnce(&'static AtomicBool) -> T + Send + 'static,
    ) -> Option<T> {
        tokio::pin!(stopped);
        let lease = tokio::select! {
            lease = self.lease() => lease?,
            () = &mut stopped => return None,
        };
        let mut guard = StopOnDrop {
            place: lease.place,
            job: lease.job,
            armed: true,
        };
        let flag = &lease.place.flag;
        let handle = tokio::task::spawn_blocking(move || {
            let out = work(flag);
            drop(lease);
            out
        });
        tokio::pin!(handle);
        let out = tokio::select! {
            out = &mut handle => out.ok(),
            () = &mut stopped => {
                stop(guard.place, guard.job);
                let _ = handle.await;
                None
            }
        };
        guard.armed = false;
        out
    }

    /// Runs `work` on a worker thread; it is never superseded.
    pub async fn run_to_end<T: Send + 'static>(
        &self,
        work: impl FnOnce(&'static AtomicBool) -> T + Send + 'static,
    ) -> Option<T> {
        self.run(std::future::pending(), work).await
    }
}

/// The most sessions kept; the one used least recently is forgotten first
/// (a page that comes back simply starts a new one).
pub const MAX_SESSIONS: usize = 64;

/// The longest session id a page may send.
pub const MAX_SESSION_ID: usize = 64;

/// One page's state: its sequence numbers and its drag.
pub struct Session {
    /// The newest run or drag's sequence number: an older one is superseded.
    edit: watch::Sender<u64>,
    /// Counts string requests: an older one is superseded.
    string: watch::Sender<u64>,
    /// The scene being dragged, with its runner's cache.
    pub drag: Mutex<Option<DragSession>>,
    used: AtomicU64,
}

impl Session {
    fn new() -> Session {
        Session {
            edit: watch::Sender::new(0),
            string: watch::Sender::new(0),
            drag: Mutex::new(None),
            used: AtomicU64::new(0),
        }
    }

    /// Records edit `seq`; whether it is the newest (an older one arriving
    /// late is not).
    pub fn begin_edit(&self, seq: u64) -> bool {
        self.edit.send_if_modified(|v| {
            let newer = seq > *v;
            if newer {
                *v = seq;
            }
            newer
        });
        *self.edit.borrow() <= seq
    }

    /// Whether an edit newer than `seq` has arrived.
    pub fn edited_since(&self, seq: u64) -> bool {
        *self.edit.borrow() > seq
    }

    /// The newest edit's sequence number.
    pub fn last_edit(&self) -> u64 {
        *self.edit.borrow()
    }

    /// Finishes when an edit newer than `seq` arrives.
    pub fn edit_after(&self, seq: u64) -> impl Future<Output = ()> + use<> {
        newer_than(self.edit.subscribe(), seq)
    }

    /// Records a new string request: its number.
    pub fn begin_string(&self) -> u64 {
        self.string.send_modify(|v| *v += 1);
        *self.string.borrow()
    }

    /// Finishes when a string request newer than `n` arrives.
    pub fn string_after(&self, n: u64) -> impl Future<Output = ()> + use<> {
        newer_than(self.string.subscribe(), n)
    }
}

/// Finishes when the value passes `seq` (never, if its sender is gone).
async fn newer_than(mut rx: watch::Receiver<u64>, seq: u64) {
    if rx.wait_for(|v| *v > seq).await.is_err() {
        std::future::pending::<()>().await;
    }
}

/// The sessions of the pages served, by the id each page makes up.
#[derive(Default)]
pub struct Sessions {
    map: Mutex<HashMap<String, Arc<Session>>>,
    clock: AtomicU64,
}

impl Sessions {
    /// The session `id`, made if new (forgetting the least recently used one
    /// when there are [`MAX_SESSIONS`]).
    pub fn get(&self, id: &str) -> Arc<Session> {
        let now = self.clock.fetch_add(1, Ordering::Relaxed);
        let mut map = self.map.lock().unwrap_or_else(PoisonError::into_inner);
        if !map.contains_key(id) && map.len() >= MAX_SESSIONS {
            let oldest = map
                .iter()
                .min_by_key(|(_, s)| s.used.load(Ordering::Relaxed))
                .map(|(k, _)| k.clone());
            if let Some(k) = oldest {
                map.remove(&k);
            }
        }
        let s = map
            .entry(id.to_string())
            .or_insert_with(|| Arc::new(Session::new()));
        s.used.store(now, Ordering::Relaxed);
        Arc::clone(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn runtime() -> tokio::runtime::Runtime {
        tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// Waits until its flag is set (at most 10 s) and says whether it was.
    fn until_stopped(flag: &'static AtomicBool) -> bool {
        for _ in 0..1000 {
            if flag.load(Ordering::SeqCst) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        false
    }

    #[test]
    fn a_superseded_job_is_stopped_and_its_worker_freed() {
        runtime().block_on(async {
            let pool = Pool::new(1);
            let session = Session::new();
            assert!(session.begin_edit(1));
            let stopped = session.edit_after(1);
            let first = pool.run(stopped, until_stopped);
            let newer = async {
                tokio::time::sleep(Duration::from_millis(50)).await;
                assert!(session.begin_edit(2));
            };
            let (out, ()) = tokio::join!(first, newer);
            assert_eq!(out, None);
            assert!(!session.begin_edit(1), "an older edit is not the newest");
            // The only worker is free again, and its flag is down.
            let second = pool.run_to_end(|f| f.load(Ordering::SeqCst)).await;
            assert_eq!(second, Some(false));
        });
    }

    #[test]
    fn a_dropped_request_stops_its_job() {
        runtime().block_on(async {
            let pool = Pool::new(1);
            let (tx, rx) = std::sync::mpsc::channel();
            let job = pool.run_to_end(move |f| {
                let _ = tx.send(until_stopped(f));
            });
            let _ = tokio::time::timeout(Duration::from_millis(50), job).await;
            let stopped = tokio::task::spawn_blocking(move || rx.recv().ok()).await;
            assert_eq!(stopped.ok().flatten(), Some(true));
        });
    }

    #[test]
    fn sessions_are_bounded() {
        let s = Sessions::default();
        for i in 0..MAX_SESSIONS + 10 {
            s.get(&i.to_string());
        }
        assert_eq!(s.map.lock().map(|m| m.len()).unwrap_or(0), MAX_SESSIONS);
    }
}
