//! Figures (placeholder, filled in next).
