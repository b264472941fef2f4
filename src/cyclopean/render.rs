//! GPU cyclopean pass: one full-screen draw into colour, middle depth and source bits.
