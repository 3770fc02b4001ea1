//! A process-wide request to stop the continuation runs in progress (Ctrl-C of a caller that
//! embeds the solver, e.g. the Python package: SIGINT is delivered to the whole process, so the
//! request is process-wide too).
//!
//! [`crate::numerics::Continuation::run`] checks [`requested`] before every step and ends with
//! [`crate::numerics::ContinuationError::Interrupted`] when it is set; analyses that run many
//! paths (limit curves, sweep values) then see each remaining path end at its next step, so the
//! whole call returns within about one continuation step per thread. The caller that set the
//! request [`clear`]s it once its call has returned. Nothing in the library sets it.

use std::sync::atomic::{AtomicBool, Ordering};

/// Whether a stop has been requested.
static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Asks every continuation run in progress (and any started before [`clear`]) to stop at its
/// next step.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Withdraws the request: runs started from now on are not stopped.
pub fn clear() {
    REQUESTED.store(false, Ordering::SeqCst);
}

/// Whether a stop has been requested and not withdrawn.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}
