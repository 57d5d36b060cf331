"""``holoradar view``: the interactive viewer in the browser, and its saved looks.

- :class:`~holoradar.app.view.session.ViewSession`: what was opened, and the
  imaging behind each picture (holoradar's own functions);
- :class:`~holoradar.app.view.settings.ViewSettings`, :func:`read_settings`,
  :func:`settings_toml`: one look as a value and as TOML (``holoradar render``);
- :func:`~holoradar.app.view.server.make_server`: the Bokeh server of the page;
- :mod:`~holoradar.app.view.browser`: headless Chromium for the tests and the
  benchmark.
"""

from .session import GlareSummary, ViewSession
from .settings import ViewSettings, read_settings, settings_toml

__all__ = ["GlareSummary", "ViewSession", "ViewSettings", "read_settings", "settings_toml"]
