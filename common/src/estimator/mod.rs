//! State estimation from raw sensors.
