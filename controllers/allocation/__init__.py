"""Chand's fuzzy task allocation (ch.5): task and robot specifications, the fuzzy inference systems
(their tables in ``data/``), task devolution and feedback coordination."""
