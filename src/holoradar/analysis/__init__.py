"""Analysis: closed-form theory and image metrics."""
