"""The shipped models' recipes, honesty checks and cards, in one place: the diagnosis model's
(:mod:`.diagnosis_model`, its card :mod:`.diagnosis_card`) and the prognostics model's
(:mod:`.prognostics_model`, its card :mod:`.prognostics_card`), both cards rendered one way
(:mod:`.cards`); ``tools/release/`` runs them."""
