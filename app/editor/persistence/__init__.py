"""What keeps the work: the record format, the crash-recovery journal and session files (no widgets)."""
