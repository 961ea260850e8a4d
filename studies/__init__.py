"""The studies behind every published table: recipes (studies/recipes/), the historical pins
(studies/pins.toml), the runner (``python -m studies NAME``) and the table scripts."""
