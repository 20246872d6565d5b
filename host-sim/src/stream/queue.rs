//! A channel between two stages bounded by the points it holds, not by its items.
//!
//! The core stage's batches vary in size (a carried line completed on its own, or most of
//! a reader's batch), and their memory is their points: a queue that counts items would
//! hold anywhere between a few and `cap × 2^15` points. This one admits an item while the
//! points it holds stay within its capacity, and always admits an item into an empty
//! queue, so an item larger than the capacity still passes. A sender blocks while the
//! queue is full, the receiver while it is empty; either end dropped ends the other's wait
//! (the sender's items come back, the receiver sees the end after the items queued).

use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

struct State<T> {
    items: VecDeque<(T, usize)>,
    points: usize,
    sender_gone: bool,
    receiver_gone: bool,
}

struct Shared<T> {
    cap: usize,
    state: Mutex<State<T>>,
    /// Signalled when an item is taken or the receiver goes.
    taken: Condvar,
    /// Signalled when an item is queued or the sender goes.
    queued: Condvar,
}

impl<T> Shared<T> {
    fn lock(&self) -> MutexGuard<'_, State<T>> {
        // A panic on the other end leaves the state consistent (every update is one
        // statement), so a poisoned lock is taken as it is.
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// The sending end of a [`channel`].
pub struct Sender<T> {
    shared: Arc<Shared<T>>,
}

/// The receiving end of a [`channel`]; an iterator over the items in the order sent.
pub struct Receiver<T> {
    shared: Arc<Shared<T>>,
}

/// A channel holding at most `cap_points` points (and one item of any size when empty).
pub fn channel<T>(cap_points: usize) -> (Sender<T>, Receiver<T>) {
    let shared = Arc::new(Shared {
        cap: cap_points,
        state: Mutex::new(State {
            items: VecDeque::new(),
            points: 0,
            sender_gone: false,
            receiver_gone: false,
        }),
        taken: Condvar::new(),
        queued: Condvar::new(),
    });
    (
        Sender {
            shared: Arc::clone(&shared),
        },
        Receiver { shared },
    )
}

impl<T> Sender<T> {
    /// Queues `item` of `points` points, waiting while the queue is too full for it;
    /// `Err(item)` when the receiver is gone.
    pub fn send(&self, item: T, points: usize) -> Result<(), T> {
        let sh = &self.shared;
        let mut st = sh.lock();
        while !st.receiver_gone && !st.items.is_empty() && st.points + points > sh.cap {
            st = sh.taken.wait(st).unwrap_or_else(|p| p.into_inner());
        }
        if st.receiver_gone {
            return Err(item);
        }
        st.points += points;
        st.items.push_back((item, points));
        drop(st);
        sh.queued.notify_one();
        Ok(())
    }
}

impl<T> Drop for Sender<T> {
    fn drop(&mut self) {
        self.shared.lock().sender_gone = true;
        self.shared.queued.notify_all();
    }
}

impl<T> Receiver<T> {
    /// The next item, waiting for one; `None` once the sender is gone and the queue empty.
    pub fn recv(&self) -> Option<T> {
        let sh = &self.shared;
        let mut st = sh.lock();
        loop {
            if let Some((item, points)) = st.items.pop_front() {
                st.points -= points;
                drop(st);
                sh.taken.notify_one();
                return Some(item);
            }
            if st.sender_gone {
                return None;
            }
            st = sh.queued.wait(st).unwrap_or_else(|p| p.into_inner());
        }
    }
}

impl<T> Iterator for Receiver<T> {
    type Item = T;

    fn next(&mut self) -> Option<T> {
        self.recv()
    }
}

impl<T> Drop for Receiver<T> {
    fn drop(&mut self) {
        let mut st = self.shared.lock();
        st.receiver_gone = true;
        // The items nobody will read are freed now, not when the sender goes.
        st.items.clear();
        st.points = 0;
        drop(st);
        self.shared.taken.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_queue_holds_its_points_and_passes_an_item_larger_than_itself() {
        let (tx, rx) = channel::<u32>(10);
        // 4 + 6 points fill it; the receiver takes them in order.
        tx.send(1, 4).expect("room");
        tx.send(2, 6).expect("room");
        let mut rx = rx;
        let got = std::thread::scope(|s| {
            let h = s.spawn(move || {
                // Waits until both are taken, then passes alone though it is larger.
                tx.send(3, 25).expect("room when empty");
            });
            let got: Vec<u32> = rx.by_ref().collect();
            h.join().expect("sender ends");
            got
        });
        assert_eq!(got, vec![1, 2, 3]);
        assert_eq!(rx.recv(), None);
    }

    #[test]
    fn a_sender_blocked_on_a_full_queue_gets_its_item_back_when_the_receiver_goes() {
        let (tx, rx) = channel::<u32>(5);
        tx.send(1, 5).expect("room");
        let back = std::thread::scope(|s| {
            let h = s.spawn(|| tx.send(2, 1));
            std::thread::sleep(std::time::Duration::from_millis(20));
            drop(rx);
            h.join().expect("sender ends")
        });
        assert_eq!(back, Err(2));
    }

    #[test]
    fn the_points_held_never_pass_the_capacity() {
        let (tx, rx) = channel::<usize>(100);
        let shared = Arc::clone(&tx.shared);
        std::thread::scope(|s| {
            s.spawn(move || {
                for k in 0..2_000usize {
                    tx.send(k, 1 + k % 37).expect("receiver reads");
                }
            });
            let mut next = 0;
            while let Some(k) = rx.recv() {
                assert_eq!(k, next);
                next += 1;
                assert!(shared.lock().points <= 100);
            }
            assert_eq!(next, 2_000);
        });
    }
}
