"""The shipped diagnosis model's recipe, honesty checks and card (:mod:`.diagnosis_model`);
``tools/release/`` runs them."""
