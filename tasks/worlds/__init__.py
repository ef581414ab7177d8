"""Worlds drawn for the missions and studies, and those with no physics at all: the random obstacle worlds
of Chand's navigation experiments with their kinematic runs, and the abstract world of Parker's L-ALLIANCE study."""
