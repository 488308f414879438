"""The reference surface: one extracted, validated and skinned mesh per body identity (seed step 6)."""
