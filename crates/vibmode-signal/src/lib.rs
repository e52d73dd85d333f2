//! vibmode-signal (work in progress).
