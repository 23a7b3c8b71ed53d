"""Problem-specific measures added to a dynamic run's summary (placeholder: the rod-impact
measures of P4 land with the Bar issue)."""


def attach(scene, summary, history):
    """Add measures that the scene's generators ask for (scene.extras) to the summary."""
    return summary
