"""What keeps the work: the record format, a document recorded and replayed, the
crash-recovery journal and session files (no widgets)."""
