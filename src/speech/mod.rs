//! Text to a talking head (in progress).
