//! vibmode-vehicle (work in progress).
