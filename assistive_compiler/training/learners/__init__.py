"""The learning algorithms' parts, on top of the learning libraries' own: SAC's layer-normalised and
conservative critics, the actor's own learning rate, its weight average, one actor per agent for a
co-optimised pair, and starting from demonstrations. The engines (:mod:`..engines`) build them in."""
