"""What the tests share: an independent reference model of the plant (plain numpy, written from
the equations, not from the package), a scan of compiled code for reference counting, and the
reference flights recorded before the package was split into layers."""
