//! vibmode-ident (work in progress).
