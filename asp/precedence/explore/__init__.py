"""Precedence from three sources: demonstrations, the CAD's geometric precedence and
experiments the planner chooses (:mod:`.knowledge`: what is known; :mod:`.select`: the next
experiment; :mod:`.oracle`: who answers it; :mod:`.learner`: the learned relation with the
support of each pair)."""
