//! vibmode-modal (work in progress).
