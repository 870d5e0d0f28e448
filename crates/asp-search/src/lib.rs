//! asp-search
