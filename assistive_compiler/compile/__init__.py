"""Compilation: render templates, lint what is written, emit the artifact."""
