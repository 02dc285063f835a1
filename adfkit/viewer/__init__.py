"""`adfkit view`: any ADF scene played live in a web browser (viser), with its controls, its
cameras' images and the replay of a recorded suture. See docs/viewer.md."""
