//! .npy writer
