//! C entry points taking a run-time polar/SVD method choice: the `_ex` variants (issue 3).
