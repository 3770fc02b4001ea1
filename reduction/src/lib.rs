//! Craig-Bampton reduction (work in progress: see the FE issue).
