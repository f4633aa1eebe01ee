"""What every target renders with: the Jinja2 environment (templating) and its filters (filters).

Layer: above model; below the targets.
"""
