"""Reward terms, observation features and preference costs (see :mod:`.registry`; all of them by
category: :mod:`.catalog`)."""
