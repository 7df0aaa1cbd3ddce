"""Training and evaluation of the diagnosis models: the window model's estimators fitted on a
dataset (:mod:`.train`), grouped cross-validation and model evaluation (:mod:`.evaluation`),
the health-check part (:mod:`.check_training`) and its evaluation on fresh units against
their baselines (:mod:`.check_evaluation`). Inference — what a trained model does with a
recording — is :mod:`prsm_health.diagnostics`; this layer is the only one of the two that
reads datasets."""
