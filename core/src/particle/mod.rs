//! MPM particle updates of augmented MPM (issue 4).
