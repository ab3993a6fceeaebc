//! Error of each method × family × precision against the reference (issue 3).
