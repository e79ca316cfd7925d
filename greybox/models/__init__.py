"""Current models: inertia plus friction (plus SVR correction)."""
