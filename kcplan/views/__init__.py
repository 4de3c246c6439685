"""Pictures of scenarios, paths and trajectories: matplotlib figures
(:mod:`kcplan.views.plots`), GIFs (:mod:`kcplan.views.animation`), self-contained HTML
pages (:mod:`kcplan.views.html`), and an arm's meshes posed along a path for all three
(:mod:`kcplan.views.arm`). Each module imports what it draws with only when used; none
imports OMPL."""
