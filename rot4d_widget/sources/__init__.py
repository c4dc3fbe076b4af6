"""The sources wing of rot4d_widget (see docs/design.md)."""
