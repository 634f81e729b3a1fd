"""Problem-agnostic building blocks shared by every environment of the suite."""
