"""Running a protocol's sessions from Python (placeholder until Session lands)."""
