"""The fitting loop: a Scene's parameters fitted to a target image with Adam, one learning
rate per parameter kind, under an image loss; and the quality metrics of a result."""
