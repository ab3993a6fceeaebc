//! C entry points of the MPM particle updates (issue 4).
