//! Single-axis family (paper 002): the plant with reaction-wheel lag and saturation. Controllers
//! connect `theta` (plant → controller) and `u` (controller → plant).

crate::fmus! {
    plant::SingleAxisPlant,
}
