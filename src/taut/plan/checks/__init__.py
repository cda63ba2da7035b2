"""What is proved or measured about a plan: verification by the quasi-static model, robustness under position error, certificates that no plan exists."""
