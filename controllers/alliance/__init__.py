"""Parker's ALLIANCE (ch.3) and L-ALLIANCE (ch.4): motivational behaviours that select each robot's active
behaviour set, learned task times, and learned acquiescence."""
