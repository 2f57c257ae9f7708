//! primo host library.
