"""Time-domain simulator of the VFF algorithm driving a CARMEL-like robot (DESIGN §5)."""
