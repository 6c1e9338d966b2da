//! A few 64-bit words written together and read whole, without locks: a sequence lock over
//! atomics. The servo thread must never wait for the haptic loop, and three separate atomics
//! let it read a force made of two successive commands; this lets it read one command whole
//! or learn that a write was under way (and render something safe instead).
//!
//! Every word is an atomic, so a read that races a write is no undefined behaviour: the
//! sequence only tells the reader whether the words it read belong together. The orderings
//! are the classic ones (a release fence after the writer claims the sequence, an acquire
//! fence before the reader checks it again).

use std::sync::atomic::{AtomicU64, Ordering, fence};

/// How many times a read retries while writes overlap it before it gives up.
const READ_TRIES: u32 = 64;

/// `N` words published as one.
pub struct SeqWords<const N: usize> {
    /// Even: the words are whole; odd: a writer is writing them.
    sequence: AtomicU64,
    words: [AtomicU64; N],
}

impl<const N: usize> SeqWords<N> {
    pub fn new(words: [u64; N]) -> Self {
        Self {
            sequence: AtomicU64::new(0),
            words: words.map(AtomicU64::new),
        }
    }

    /// Replaces the words. Writers take turns (a second writer spins while one writes), so
    /// any number of threads may write.
    pub fn write(&self, words: [u64; N]) {
        let claimed = self.claim();
        fence(Ordering::Release);
        for (slot, word) in self.words.iter().zip(words) {
            slot.store(word, Ordering::Relaxed);
        }
        self.sequence.store(claimed + 1, Ordering::Release);
    }

    /// Makes the sequence odd for this writer; the odd value it set.
    fn claim(&self) -> u64 {
        let mut sequence = self.sequence.load(Ordering::Relaxed);
        loop {
            if sequence % 2 == 1 {
                std::hint::spin_loop();
                sequence = self.sequence.load(Ordering::Relaxed);
                continue;
            }
            match self.sequence.compare_exchange_weak(
                sequence,
                sequence + 1,
                Ordering::Acquire,
                Ordering::Relaxed,
            ) {
                Ok(_) => return sequence + 1,
                Err(now) => sequence = now,
            }
        }
    }

    /// The words as one write left them, or `None` when writes kept overlapping the read (a
    /// writer preempted halfway): the reader never waits longer than a few dozen loads.
    pub fn read(&self) -> Option<[u64; N]> {
        for _ in 0..READ_TRIES {
            let before = self.sequence.load(Ordering::Acquire);
            if before % 2 == 1 {
                std::hint::spin_loop();
                continue;
            }
            let words = std::array::from_fn(|k| self.words[k].load(Ordering::Relaxed));
            fence(Ordering::Acquire);
            if self.sequence.load(Ordering::Relaxed) == before {
                return Some(words);
            }
        }
        None
    }
}
