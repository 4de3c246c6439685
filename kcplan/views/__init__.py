"""Pictures of scenarios, paths and trajectories: matplotlib figures
(:mod:`kcplan.views.plots`), GIFs (:mod:`kcplan.views.animation`), self-contained HTML
pages (:mod:`kcplan.views.html`), and for all three an arm's meshes posed along a path
(:mod:`kcplan.views.arm`) and a sensed cloud's points thinned for display
(:mod:`kcplan.views.clouds`). Each module imports what it draws with only when used; none
imports OMPL."""
