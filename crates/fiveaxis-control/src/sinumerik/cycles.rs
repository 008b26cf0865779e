//! The SINUMERIK cycles the control carries out itself (placeholder for
//! the cycles module).
