//! asp-gen
