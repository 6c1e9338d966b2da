//! A global allocator that counts what one thread allocates while it is armed: how many
//! allocations, and the largest. Shared by the test binaries that check what the haptic tick
//! allocates and what a file's reader allocates before it has checked the file's sizes.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting the armed thread's allocations.
pub struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<u64> = const { Cell::new(0) };
    static LARGEST: Cell<usize> = const { Cell::new(0) };
    static HOOK: Cell<Option<fn()>> = const { Cell::new(None) };
}

/// What a measured stretch of one thread's work allocated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Allocated {
    pub count: u64,
    pub largest_bytes: usize,
}

fn note(size: usize) {
    let _ = ARMED.try_with(|armed| {
        if !armed.get() {
            return;
        }
        COUNT.with(|count| count.set(count.get() + 1));
        LARGEST.with(|largest| largest.set(largest.get().max(size)));
        if let Some(hook) = HOOK.with(Cell::get) {
            // The hook may allocate (a backtrace): it is not counted.
            armed.set(false);
            hook();
            armed.set(true);
        }
    });
}

// SAFETY: every call goes to the system allocator unchanged; counting touches thread-locals
// that need no allocation.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Starts counting this thread's allocations afresh.
pub fn arm() {
    COUNT.with(|count| count.set(0));
    LARGEST.with(|largest| largest.set(0));
    ARMED.with(|armed| armed.set(true));
}

/// Pauses counting (what was counted stays).
pub fn pause() {
    ARMED.with(|armed| armed.set(false));
}

/// Goes on counting, adding to what was counted.
pub fn resume() {
    ARMED.with(|armed| armed.set(true));
}

/// What was counted since [`arm`].
pub fn allocated() -> Allocated {
    Allocated {
        count: COUNT.with(Cell::get),
        largest_bytes: LARGEST.with(Cell::get),
    }
}

/// Calls `hook` at each counted allocation on this thread (uncounted itself), or no more.
pub fn on_allocation(hook: Option<fn()>) {
    HOOK.with(|h| h.set(hook));
}

/// `work`'s result, and what it allocated on this thread.
pub fn measure<R>(work: impl FnOnce() -> R) -> (R, Allocated) {
    arm();
    let result = work();
    pause();
    (result, allocated())
}
