//! vibmode-report (work in progress).
