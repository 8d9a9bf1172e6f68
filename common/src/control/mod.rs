//! The successive-loop-closure autopilot of the thesis (chapter 3).
