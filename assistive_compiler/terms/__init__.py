"""Reward terms, observation features and preference costs (see :mod:`.registry`)."""
