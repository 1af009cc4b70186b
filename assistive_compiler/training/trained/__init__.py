"""A trained run, after training: evaluated as the paper evaluates (:mod:`.evaluate`) and exported
as a shipped, NumPy-only policy (:mod:`.export`)."""
