//! vibmode-spectra (work in progress).
