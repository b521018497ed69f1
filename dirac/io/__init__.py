"""Files users write and read: scene files and result files."""
